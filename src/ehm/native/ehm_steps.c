/* The nonlinear route's stepping loop in C (ehm.engine.stepper._advancer), so that Python is outside the per-step loop.
 *
 * Written for ehm (MIT licence).  ehm compiles this file at first use (ehm.engine.native) against the MuJoCo that the
 * `mujoco` wheel installed, and calls it through ctypes with the addresses of the Python bindings' mjModel and
 * mjData: the same library, the same structures.
 *
 * ehm_advance runs steps lo .. hi - 1 exactly as the Python loop does, operation for operation:
 *     gravity = G0 - a_seat_i           (the d'Alembert seat load: `gravity` holds G0 - a_seat, one row per step)
 *     [rotating seat: the hinges' set-points and feed-forward torques of step i]
 *     mj_step
 *     [head-in-space control: ehm.engine.control.after_step]
 *     sens[i] = sensordata              (the sensors of the step's start state)
 * and leaves gravity as the last step had it (the caller restores G0).  MuJoCo's profiling clock (mjcb_time, which the
 * Python bindings set, and whose readings only fill d->timer) is off while any thread runs the loop: about 0.5 us of
 * each step.  A MuJoCo error inside the loop comes back as -1 and its message (ehm_last_error), as the Python
 * bindings turn it into an exception, instead of MuJoCo's default (print and end the process); the handler is this
 * file's while any thread runs the loop, and passes other threads' errors on to the one before it.  The head control's constants come in the
 * order of ehm.engine.control.NUMERIC_FIELDS; the line and the reference up live in d->userdata, as in Python and in
 * the native FMU (ehm_fmu.c), which share ehm_head_control.h.
 */

#include <pthread.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mujoco/mujoco.h>

#include "ehm_head_control.h"

#if defined(_WIN32)
#define EHM_EXPORT __declspec(dllexport)
#else
#define EHM_EXPORT __attribute__((visibility("default")))
#endif

static _Thread_local jmp_buf *error_jump = NULL;
static _Thread_local char error_text[512];
static pthread_mutex_t shared_lock = PTHREAD_MUTEX_INITIALIZER;
static int loop_users = 0;
static mjfTime saved_clock = NULL;
static void (*saved_error)(const char *) = NULL;

static void on_error(const char *msg) {
    if (error_jump) {
        snprintf(error_text, sizeof error_text, "%s", msg);
        longjmp(*error_jump, 1);
    }
    if (saved_error) {
        saved_error(msg);
    } else {
        fprintf(stderr, "MuJoCo error: %s\n", msg);
        exit(1); /* MuJoCo's own default */
    }
}

/* The first thread into the loop turns the clock off and installs the error handler; the last one out puts both
 * back. */
static void enter(void) {
    pthread_mutex_lock(&shared_lock);
    if (loop_users++ == 0) {
        saved_clock = mjcb_time;
        mjcb_time = NULL;
        saved_error = mju_user_error;
        mju_user_error = on_error;
    }
    pthread_mutex_unlock(&shared_lock);
}

static void leave(void) {
    pthread_mutex_lock(&shared_lock);
    if (--loop_users == 0) {
        mjcb_time = saved_clock;
        mju_user_error = saved_error;
    }
    pthread_mutex_unlock(&shared_lock);
}

/* The message of this thread's last MuJoCo error in ehm_advance. */
EHM_EXPORT const char *ehm_last_error(void) { return error_text; }

static void steps(const mjModel *m, mjData *d, const double *gravity, double *sens, long lo, long hi,
                  const double *ctrl, int ctrl_adr, const double *ff, int ff_adr, const double *control) {
    mjtNum *g = ((mjModel *)m)->opt.gravity;
    const int nsens = m->nsensordata;
    long i;
    int k;
    for (i = lo; i < hi; i++) {
        for (k = 0; k < 3; k++) g[k] = gravity[3 * i + k];
        if (ctrl) {
            for (k = 0; k < 6; k++) d->ctrl[ctrl_adr + k] = ctrl[6 * i + k];
            for (k = 0; k < 3; k++) d->qfrc_applied[ff_adr + k] = ff[3 * i + k];
        }
        mj_step(m, d);
        if (control) ehm_head_control_after_step(m, d, control);
        memcpy(sens + (size_t)i * (size_t)nsens, d->sensordata, (size_t)nsens * sizeof(mjtNum));
    }
}

/* Steps lo .. hi - 1.  gravity (n, 3) and sens (n, nsensordata) are C-ordered arrays of the whole run; ctrl (n, 6)
 * and ff (n, 3) the rotating seat's set-points and feed-forward torques written into d->ctrl from ctrl_adr and
 * d->qfrc_applied from ff_adr (ctrl NULL: no seat drive); control: the head control's constants (NULL: none).
 * Returns the number of steps run, or -1 after a MuJoCo error (ehm_last_error). */
EHM_EXPORT long ehm_advance(const mjModel *m, mjData *d, const double *gravity, double *sens, long lo, long hi,
                            const double *ctrl, int ctrl_adr, const double *ff, int ff_adr, const double *control) {
    jmp_buf here;
    volatile long rc = -1;
    error_text[0] = 0;
    enter();
    if (setjmp(here) == 0) {
        error_jump = &here;
        steps(m, d, gravity, sens, lo, hi, ctrl, ctrl_adr, ff, ff_adr, control);
        rc = hi - lo;
    }
    error_jump = NULL;
    leave();
    return rc;
}
