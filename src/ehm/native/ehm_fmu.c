/* FMI 2.0 co-simulation slave of the ehm seated human, on the MuJoCo C API.
 *
 * Written for ehm (MIT licence).  `ehm export-fmu` compiles this file together with a generated header
 * (ehm_fmu_config.h: GUID and variable names) against the MuJoCo shipped by the `mujoco` Python wheel,
 * and puts the compiled model (resources/ehm_model.mjb) and the settled state (resources/ehm_state.txt)
 * next to it.  No Python is involved when the unit runs.
 *
 * One model step is exactly one step of ehm's Python engine (ehm.engine.step / run): the seat translation
 * is a d'Alembert load, gravity = G0 - a_seat, then mj_step.  Output sample i belongs to the state at the
 * start of step i (t_i = t0 + i dt); its accelerations are taken over the step,
 *     linear:  (v_{i+1} - v_i) / dt + a_seat_i      (v: the site's framelinvel sensor, world = seat axes)
 *     angular: (w_{i+1} - w_i) / dt                 (w: the site's frameangvel sensor, world axes)
 * (ehm.engine.point_accelerations).  doStep(t, h) runs h / dt model steps with the inputs held and leaves
 * the sample of its last step in the outputs (output_time_s = t + h - dt); v_{i+1} of that step comes from
 * the velocity-stage kinematics and sensors of the new state (ehm.engine.evaluate_velocities).
 *
 * Value references: inputs 0 .. EHM_N_INPUTS-1 (seat_a{x,y,z}_mps2, seat_w{x,y,z}_radps), then the
 * outputs in the order of compute_outputs() below.
 *
 * A unit exported with a rotating seat (resources/ehm_state.txt has a 'rotating_seat' line) drives the seat's
 * yaw, pitch and roll hinges from the angular velocity inputs (seat axes, held over the communication step), as
 * ehm.engine.run does with a seat rotation: per model step, the seat attitude q (seat -> world) at the step's
 * start gives the z-y-x angles (yaw unwrapped), the body rates give the angle rates, their change over the last
 * model step the angle accelerations (backward difference: the unit sees no future inputs); the hinges get the
 * angles and rates as set-points and I * accelerations as feed-forward torque, gravity is G0 - R a_seat, and q
 * advances by the held rates, q <- q exp(w dt / 2).  Outputs are then in seat axes (R^T applied) and rotations are
 * taken relative to the seat, as ehm.simulation.SeatedHuman reports them.
 */

#include <math.h>
#include <pthread.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include <mujoco/mujoco.h>

#include "ehm_fmu_config.h"
#include "ehm_head_control.h"

#define EHM_MAX_POINTS 8
#define EHM_MAX_GROUPS 8
#define EHM_MAX_SURFACES 8
#define EHM_POINT_OUTPUTS 15  /* a{x,y,z}, roll, pitch, yaw, {x,y,z}, w{x,y,z}, {roll,pitch,yaw}_acc */
#define EHM_MSG 1024
#define EHM_STATE_MAGIC 4.2e7  /* first number of a serialized FMU state */
#define EHM_MAX_SEAT_RATE 20.0 /* largest seat angular velocity a rotating-seat unit takes [rad/s] */

static const double G0[3] = {0.0, 0.0, -9.81}; /* standard gravity in the seat frame [m/s^2], as ehm.engine.G0 */

typedef enum { PHASE_INSTANTIATED, PHASE_INITIALIZATION, PHASE_STEPPING, PHASE_TERMINATED } Phase;

typedef struct {
    char name[64];
    int pos, quat, linvel, angvel;      /* sensordata addresses of <point>_framepos, _framequat, ... */
    mjtNum pos0[3], quat0_inv[4];       /* settled position [m], inverse of the settled orientation */
} Point;

/* A rotating seat: its hinges and the attitude the unit integrates from the angular velocity inputs. */
typedef struct {
    int on;                             /* 1: the model has a rotating seat */
    int dof[3], ctrl[3];                /* dof and first control address of the yaw, pitch, roll hinges */
    double inertia;                     /* the seat's moment of inertia about each hinge [kg m^2] */
    mjtNum pivot[3];                    /* the seat's pivot (world, settled) [m] */
    /* kinematic state */
    mjtNum q[4];                        /* attitude at the next step's start, seat -> world (w x y z) */
    double yaw, pitch;                  /* unwrapped yaw and pitch of the last step's start [rad] */
    double rates[3];                    /* angle rates (yaw', pitch', roll') of the last step's start [rad/s] */
    int started;                        /* 0 until the first step: no previous rates */
} Seat;

typedef struct {
    char name[64];
    int n, sensor[EHM_MAX_SURFACES];    /* sensordata addresses of support_<surface> for its seat surfaces */
} Group;

/* What the outputs of one sample take from the state at the sample's start (copied after mj_step). */
typedef struct {
    mjtNum pos[EHM_MAX_POINTS][3], quat[EHM_MAX_POINTS][4], linvel[EHM_MAX_POINTS][3], angvel[EHM_MAX_POINTS][3];
    mjtNum support[EHM_MAX_GROUPS][3];
    mjtNum seat_q[4];                   /* the seat's attitude at the sample, seat -> world (unit for a static seat) */
} Sample;

typedef struct {
    /* host */
    fmi2CallbackFunctions cb;
    char instance[128];
    int logging_on;
    /* model, resources */
    mjModel *m;
    mjData *d;
    char *broken;                       /* why the resources cannot be used (NULL: they can) */
    double dt;                          /* model step [s] */
    int nq, nv, na;
    mjtNum *qpos0, *qvel0, *act0;       /* the settled state */
    int npoints, ngroups;
    Point point[EHM_MAX_POINTS];
    Group group[EHM_MAX_GROUPS];
    int pelvis_adr;                     /* qpos address of the pelvis free joint */
    double diverged_m, max_seat_acc;
    /* co-simulation */
    Phase phase;
    double t0;
    long long steps;                    /* model steps done since t0 */
    double u[EHM_N_INPUTS], y[EHM_N_OUTPUTS];
    int outputs_valid;
    char failed[EHM_MSG];               /* why the model cannot go on (divergence, MuJoCo error); "" if it can */
    int nstate;                         /* mj_stateSize(mjSTATE_INTEGRATION) */
    mjtNum *scratch;                    /* a state buffer for the initial outputs ... */
    Seat scratch_seat;                  /* ... with the seat's kinematic state */
    int pos_ready;                      /* 1: the position stage of the current state is done (evaluate_velocities) */
    Seat seat;
    mjtNum seat_q[4];                   /* seat attitude at the start of the step being taken */
    const mjtNum *head_control;         /* the numeric ehm_head_control (NULL: no head-in-space control) */
} Ehm;

typedef struct {
    int nstate;
    Seat seat;
    mjtNum *mj;
    long long steps;
    double t0, u[EHM_N_INPUTS], y[EHM_N_OUTPUTS];
    int outputs_valid;
    char failed[EHM_MSG];
} Snapshot;

/* ------------------------------------------------------------------------------------------------ logging */

static void logmsg(Ehm *e, fmi2Status status, const char *category, const char *fmt, ...) {
    char text[EHM_MSG], esc[2 * EHM_MSG];
    va_list ap;
    size_t i, j;
    if (!e || !e->cb.logger || (status == fmi2OK && !e->logging_on)) return;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    for (i = 0, j = 0; text[i] && j < sizeof esc - 2; i++) { /* the logger takes a format: escape '%' */
        if (text[i] == '%') esc[j++] = '%';
        esc[j++] = text[i];
    }
    esc[j] = '\0';
    e->cb.logger(e->cb.componentEnvironment, e->instance, status, category, esc);
}

#define LOG_ERROR(e, ...) logmsg((e), fmi2Error, "logStatusError", __VA_ARGS__)
#define LOG_DISCARD(e, ...) logmsg((e), fmi2Discard, "logStatusDiscard", __VA_ARGS__)
#define LOG_WARNING(e, ...) logmsg((e), fmi2Warning, "logStatusWarning", __VA_ARGS__)
#define LOG_INFO(e, ...) logmsg((e), fmi2OK, "logEvents", __VA_ARGS__)

/* ------------------------------------------------- MuJoCo errors and warnings: into the host's log, no exit */
/* MuJoCo reports fatal errors through the global mju_user_error (by default: print and exit the process) and
 * warnings through mju_user_warning (by default: print and append to MUJOCO_LOG.TXT).  While this unit is
 * inside MuJoCo (guarded() below), its own handlers are installed: an error becomes an fmi2Error of the call
 * (longjmp back out of MuJoCo) and a warning a log message.  Outside, the handlers that were there before
 * (the host's, if it uses MuJoCo too) are back in place; a call of another thread meanwhile is passed on to
 * them. */

static _Thread_local jmp_buf *guard_jump = NULL;
static _Thread_local Ehm *guard_ehm = NULL;
static pthread_mutex_t handlers_lock = PTHREAD_MUTEX_INITIALIZER;
static int handler_users = 0;
static void (*previous_error)(const char *) = NULL;
static void (*previous_warning)(const char *) = NULL;

static void on_mujoco_error(const char *msg) {
    if (guard_jump) {
        snprintf(guard_ehm->failed, sizeof guard_ehm->failed, "MuJoCo error: %s", msg);
        longjmp(*guard_jump, 1);
    }
    if (previous_error) {
        previous_error(msg);
    } else {
        fprintf(stderr, "MuJoCo error: %s\n", msg);
        exit(1); /* MuJoCo's own default */
    }
}

static void on_mujoco_warning(const char *msg) {
    if (guard_ehm) {
        LOG_WARNING(guard_ehm, "MuJoCo: %s", msg);
    } else if (previous_warning) {
        previous_warning(msg);
    } else {
        fprintf(stderr, "MuJoCo warning: %s\n", msg);
    }
}

static void handlers_acquire(void) {
    pthread_mutex_lock(&handlers_lock);
    if (handler_users++ == 0) {
        previous_error = mju_user_error;
        previous_warning = mju_user_warning;
        mju_user_error = on_mujoco_error;
        mju_user_warning = on_mujoco_warning;
    }
    pthread_mutex_unlock(&handlers_lock);
}

static void handlers_release(void) {
    pthread_mutex_lock(&handlers_lock);
    if (--handler_users == 0) {
        mju_user_error = previous_error;
        mju_user_warning = previous_warning;
    }
    pthread_mutex_unlock(&handlers_lock);
}

/* Run work(e, arg) inside MuJoCo with this unit's handlers; returns work's result, or -1 after a MuJoCo
 * error (the reason is then in e->failed). */
static int guarded(Ehm *e, int (*work)(Ehm *, void *), void *arg) {
    jmp_buf here;
    volatile int rc = -1;
    handlers_acquire();
    if (setjmp(here) == 0) {
        guard_jump = &here;
        guard_ehm = e;
        rc = work(e, arg);
    }
    guard_jump = NULL;
    guard_ehm = NULL;
    handlers_release();
    return rc;
}

/* -------------------------------------------------------------------------------------------- resources */

static char *dupstr(const char *s) {
    size_t n = strlen(s) + 1;
    char *c = malloc(n);
    if (c) memcpy(c, s, n);
    return c;
}

/* Local path of a file: URI ("file:///a/b", "file://localhost/a/b", "file:/a/b"), percent-decoded. */
static int uri_to_path(const char *uri, char *path, size_t size) {
    const char *p;
    size_t j = 0;
    if (!uri) return -1;
    if (strncmp(uri, "file://localhost/", 17) == 0) p = uri + 16;
    else if (strncmp(uri, "file:///", 8) == 0) p = uri + 7;
    else if (strncmp(uri, "file:/", 6) == 0) p = uri + 5;
    else return -1;
    for (; *p && j + 1 < size; p++) {
        if (p[0] == '%' && p[1] && p[2]) {
            char hex[3] = {p[1], p[2], 0};
            char *end;
            long v = strtol(hex, &end, 16);
            if (*end) return -1;
            path[j++] = (char)v;
            p += 2;
        } else {
            path[j++] = *p;
        }
    }
    path[j] = '\0';
    while (j > 1 && path[j - 1] == '/') path[--j] = '\0';
    return *p ? -1 : 0;
}

typedef struct { FILE *f; const char *path; char *why; size_t why_size; } Reader;

static int read_word(Reader *r, char *word, size_t size) {
    int c;
    size_t n = 0;
    word[0] = '\0';
    for (;;) { /* skip blanks and # comments */
        c = fgetc(r->f);
        if (c == '#') { while (c != '\n' && c != EOF) c = fgetc(r->f); }
        if (c == EOF) return -1;
        if (c != ' ' && c != '\n' && c != '\t' && c != '\r') break;
    }
    while (c != EOF && c != ' ' && c != '\n' && c != '\t' && c != '\r') {
        if (n + 1 < size) word[n++] = (char)c;
        c = fgetc(r->f);
    }
    word[n] = '\0';
    return 0;
}

static int read_number(Reader *r, const char *what, double *out) {
    char word[64], *end;
    if (read_word(r, word, sizeof word) < 0) {
        snprintf(r->why, r->why_size, "%s: ends before %s", r->path, what);
        return -1;
    }
    *out = strtod(word, &end);
    if (*end || !isfinite(*out)) {
        snprintf(r->why, r->why_size, "%s: %s is '%s', not a finite number", r->path, what, word);
        return -1;
    }
    return 0;
}

/* "key value" */
static int read_keyed(Reader *r, const char *key, double *out) {
    char word[64];
    if (read_word(r, word, sizeof word) < 0 || strcmp(word, key) != 0) {
        snprintf(r->why, r->why_size, "%s: expected '%s', found '%s'", r->path, key, word);
        return -1;
    }
    return read_number(r, key, out);
}

static int read_vector(Reader *r, const char *key, int expected, mjtNum *out) {
    char word[64];
    double n;
    int i;
    if (read_word(r, word, sizeof word) < 0 || strcmp(word, key) != 0) {
        snprintf(r->why, r->why_size, "%s: expected '%s', found '%s'", r->path, key, word);
        return -1;
    }
    if (read_number(r, key, &n) < 0) return -1;
    if ((int)n != expected) {
        snprintf(r->why, r->why_size, "%s: %s has %d values, the model needs %d", r->path, key, (int)n, expected);
        return -1;
    }
    for (i = 0; i < expected; i++)
        if (read_number(r, key, &out[i]) < 0) return -1;
    return 0;
}

static int sensor_adr(Ehm *e, const char *point, const char *kind, int *adr, char *why, size_t size) {
    char name[160];
    int id;
    snprintf(name, sizeof name, "%s_%s", point, kind);
    id = mj_name2id(e->m, mjOBJ_SENSOR, name);
    if (id < 0) {
        snprintf(why, size, "the model has no sensor %s", name);
        return -1;
    }
    *adr = e->m->sensor_adr[id];
    return 0;
}

/* 'rotating_seat <inertia> <pivot x y z>': the seat's hinges seat.yaw, seat.pitch, seat.roll and their tracking
 * actuators seat_yaw, seat_pitch, seat_roll (ehm.engine.build with rotating_seat=True). */
static int read_seat(Ehm *e, Reader *r) {
    static const char *const dofs[3] = {"yaw", "pitch", "roll"};
    char name[64];
    int k, j;
    Seat *st = &e->seat;
    if (read_number(r, "the seat inertia", &st->inertia) < 0) return -1;
    for (k = 0; k < 3; k++) if (read_number(r, "the seat pivot", &st->pivot[k]) < 0) return -1;
    for (k = 0; k < 3; k++) {
        snprintf(name, sizeof name, "seat.%s", dofs[k]);
        j = mj_name2id(e->m, mjOBJ_JOINT, name);
        if (j < 0) { snprintf(r->why, r->why_size, "the model has no seat hinge %s", name); return -1; }
        st->dof[k] = e->m->jnt_dofadr[j];
        snprintf(name, sizeof name, "seat_%s", dofs[k]);
        j = mj_name2id(e->m, mjOBJ_ACTUATOR, name);
        if (j < 0) { snprintf(r->why, r->why_size, "the model has no seat actuator %s", name); return -1; }
        st->ctrl[k] = e->m->actuator_ctrladr[j];  /* position set-point, then velocity set-point */
    }
    st->on = 1;
    return 0;
}

/* Read resources/ehm_state.txt (written by ehm.interfaces.fmu_native): the settled state, the output points with their
 * settled poses, the support groups, the divergence and input limits. */
static int read_state(Ehm *e, const char *path, char *why, size_t size) {
    Reader r = {NULL, path, why, size};
    char word[128];
    double v;
    int rc = -1;
    r.f = fopen(path, "r");
    if (!r.f) {
        snprintf(why, size, "cannot open %s", path);
        return -1;
    }
    if (read_word(&r, word, sizeof word) < 0 || strcmp(word, "ehm_native_fmu_state") != 0 ||
        read_number(&r, "the format", &v) < 0 || v != 1) {
        snprintf(why, size, "%s is not an ehm native FMU state file of format 1", path);
        goto done;
    }
    if (read_keyed(&r, "dt_s", &v) < 0) goto done;
    if (v != e->m->opt.timestep) {
        snprintf(why, size, "%s: the time step %g s differs from the model's %g s", path, v, e->m->opt.timestep);
        goto done;
    }
    if (read_vector(&r, "qpos", e->nq, e->qpos0) < 0 || read_vector(&r, "qvel", e->nv, e->qvel0) < 0 ||
        read_vector(&r, "act", e->na, e->act0) < 0)
        goto done;
    if (read_keyed(&r, "diverged_m", &e->diverged_m) < 0 || read_keyed(&r, "max_seat_acc_mps2", &e->max_seat_acc) < 0)
        goto done;
    e->npoints = e->ngroups = 0;
    for (;;) {
        if (read_word(&r, word, sizeof word) < 0) {
            snprintf(why, size, "%s: ends without 'end'", path);
            goto done;
        }
        if (strcmp(word, "end") == 0) break;
        if (strcmp(word, "point") == 0) {
            Point *p = &e->point[e->npoints];
            mjtNum q0[4];
            int j;
            if (e->npoints == EHM_MAX_POINTS) { snprintf(why, size, "%s: too many points", path); goto done; }
            read_word(&r, p->name, sizeof p->name);
            for (j = 0; j < 3; j++) if (read_number(&r, "a settled position", &p->pos0[j]) < 0) goto done;
            for (j = 0; j < 4; j++) if (read_number(&r, "a settled quaternion", &q0[j]) < 0) goto done;
            mju_negQuat(p->quat0_inv, q0);
            if (sensor_adr(e, p->name, "framepos", &p->pos, why, size) < 0 ||
                sensor_adr(e, p->name, "framequat", &p->quat, why, size) < 0 ||
                sensor_adr(e, p->name, "framelinvel", &p->linvel, why, size) < 0 ||
                sensor_adr(e, p->name, "frameangvel", &p->angvel, why, size) < 0)
                goto done;
            e->npoints++;
        } else if (strcmp(word, "group") == 0) {
            Group *g = &e->group[e->ngroups];
            double n;
            int j;
            if (e->ngroups == EHM_MAX_GROUPS) { snprintf(why, size, "%s: too many support groups", path); goto done; }
            read_word(&r, g->name, sizeof g->name);
            if (read_number(&r, "a surface count", &n) < 0) goto done;
            if (n < 0 || n > EHM_MAX_SURFACES) { snprintf(why, size, "%s: bad surface count", path); goto done; }
            g->n = (int)n;
            for (j = 0; j < g->n; j++) {
                read_word(&r, word, sizeof word);
                if (sensor_adr(e, "support", word, &g->sensor[j], why, size) < 0) goto done;
            }
            e->ngroups++;
        } else if (strcmp(word, "rotating_seat") == 0) {
            if (read_seat(e, &r) < 0) goto done;
        } else {
            snprintf(why, size, "%s: unknown entry '%s'", path, word);
            goto done;
        }
    }
    if (e->npoints * EHM_POINT_OUTPUTS + 3 * e->ngroups + 1 != EHM_N_OUTPUTS) {
        snprintf(why, size, "%s: %d points and %d support groups do not make this unit's %d outputs", path,
                 e->npoints, e->ngroups, EHM_N_OUTPUTS);
        goto done;
    }
    rc = 0;
done:
    fclose(r.f);
    return rc;
}

typedef struct { const char *dir; char *why; size_t size; } LoadArgs;

static int load_work(Ehm *e, void *arg) {
    LoadArgs *a = arg;
    char path[4200];
    int j;
    snprintf(path, sizeof path, "%s/ehm_model.mjb", a->dir);
    e->m = mj_loadModel(path, NULL);
    if (!e->m) {
        snprintf(a->why, a->size, "cannot load the MuJoCo model %s (missing, or not an MJB of MuJoCo %s)", path,
                 mj_versionString());
        return -1;
    }
    e->d = mj_makeData(e->m);
    if (!e->d) { snprintf(a->why, a->size, "MuJoCo could not allocate the model's data"); return -1; }
    e->dt = e->m->opt.timestep;
    e->nq = (int)e->m->nq;
    e->nv = (int)e->m->nv;
    e->na = (int)e->m->na;
    e->qpos0 = calloc(e->nq + 1, sizeof(mjtNum));
    e->qvel0 = calloc(e->nv + 1, sizeof(mjtNum));
    e->act0 = calloc(e->na + 1, sizeof(mjtNum));
    e->nstate = mj_stateSize(e->m, mjSTATE_INTEGRATION);
    e->scratch = calloc(e->nstate, sizeof(mjtNum));
    if (!e->qpos0 || !e->qvel0 || !e->act0 || !e->scratch) { snprintf(a->why, a->size, "out of memory"); return -1; }
    j = mj_name2id(e->m, mjOBJ_JOINT, "pelvis");
    if (j < 0) { snprintf(a->why, a->size, "the model has no pelvis joint"); return -1; }
    e->pelvis_adr = e->m->jnt_qposadr[j];
    j = mj_name2id(e->m, mjOBJ_NUMERIC, "ehm_head_control");
    e->head_control = j < 0 ? NULL : e->m->numeric_data + e->m->numeric_adr[j];
    snprintf(path, sizeof path, "%s/ehm_state.txt", a->dir);
    return read_state(e, path, a->why, a->size);
}

static int load_resources(Ehm *e, const char *uri) {
    char dir[4096], why[EHM_MSG] = "";
    LoadArgs a = {dir, why, sizeof why};
    if (uri_to_path(uri, dir, sizeof dir) < 0) {
        snprintf(why, sizeof why, "the resource location '%s' is not a local file: URI", uri ? uri : "(none)");
    } else if (guarded(e, load_work, &a) == 0) {
        return 0;
    } else if (!why[0]) {
        snprintf(why, sizeof why, "%s", e->failed);
    }
    e->broken = dupstr(why);
    e->failed[0] = '\0';
    LOG_ERROR(e, "bad resources: %s; export the unit again with 'ehm export-fmu'.", why);
    return -1;
}

/* -------------------------------------------------------------------------------------- the model step */

/* Head-in-space control (ehm.engine.control): the numeric ehm_head_control holds delay_steps, head_body,
 * torso_body, quat_adr, angvel_adr (sensordata), tilt stiffness, tilt damping, yaw damping (ehm_head_control.h's
 * HC_ names); userdata holds the reference up (head axes) and the line of the last N - 1 torques, oldest first.  The
 * law after each step is ehm_head_control_after_step, shared with ehm's compiled stepping loop. */

/* Start the law in the current state (ehm.engine.control.start): its head orientation the reference. */
static void head_control_start(Ehm *e) {
    const mjtNum ez[3] = {0, 0, 1};
    mjtNum qc[4];
    if (!e->head_control) return;
    mju_negQuat(qc, e->d->sensordata + (int)e->head_control[HC_QUAT]);
    mju_zero(e->d->userdata, e->m->nuserdata);
    mju_rotVecQuat(e->d->userdata, ez, qc);
}

/* The settled state at the unit's start time, as ehm.engine.settled_data. */
static void to_settled(Ehm *e) {
    mj_resetData(e->m, e->d);
    mju_copy(e->d->qpos, e->qpos0, e->nq);
    mju_copy(e->d->qvel, e->qvel0, e->nv);
    mju_copy(e->d->act, e->act0, e->na);
    mj_forward(e->m, e->d);
    head_control_start(e);
    e->pos_ready = 0;
    mju_unit4(e->seat.q);
    e->seat.yaw = 0.0;
    e->seat.rates[0] = e->seat.rates[1] = e->seat.rates[2] = 0.0;
    e->seat.started = 0;
}

static int settled_work(Ehm *e, void *arg) {
    (void)arg;
    to_settled(e);
    return 0;
}

/* The seat's hinge set-points and feed-forward torque for the step starting now, from the attitude at its start
 * and the held body rates w [rad/s] (ehm.inputs.motion.seat_kinematics, with a backward difference for the angle
 * accelerations); then the attitude advances over the step. */
static void seat_drive(Ehm *e, const double w[3]) {
    Seat *st = &e->seat;
    const mjtNum *q = st->q;
    double yaw, pitch, roll, sr, cr, rates[3], acc[3], turn;
    int k;
    yaw = atan2(2 * (q[0] * q[3] + q[1] * q[2]), 1 - 2 * (q[2] * q[2] + q[3] * q[3]));
    pitch = asin(fmax(-1.0, fmin(1.0, 2 * (q[0] * q[2] - q[3] * q[1]))));
    roll = atan2(2 * (q[0] * q[1] + q[2] * q[3]), 1 - 2 * (q[1] * q[1] + q[2] * q[2]));
    if (st->started) yaw = st->yaw + remainder(yaw - st->yaw, 2 * mjPI);  /* unwrapped */
    sr = sin(roll);
    cr = cos(roll);
    turn = w[1] * sr + w[2] * cr;
    rates[0] = turn / cos(pitch);                  /* yaw' */
    rates[1] = w[1] * cr - w[2] * sr;              /* pitch' */
    rates[2] = w[0] + tan(pitch) * turn;           /* roll' */
    for (k = 0; k < 3; k++) acc[k] = st->started ? (rates[k] - st->rates[k]) / e->dt : 0.0;
    {
        const double angles[3] = {yaw, pitch, roll};
        for (k = 0; k < 3; k++) {
            e->d->ctrl[st->ctrl[k]] = angles[k];
            e->d->ctrl[st->ctrl[k] + 1] = rates[k];
            e->d->qfrc_applied[st->dof[k]] = st->inertia * acc[k];
        }
    }
    st->yaw = yaw;
    st->pitch = pitch;
    for (k = 0; k < 3; k++) st->rates[k] = rates[k];
    st->started = 1;
    mju_quatIntegrate(st->q, w, e->dt);
}

/* One model step with the seat acceleration a [m/s^2] held: the d'Alembert seat load as gravity (ehm.engine.step).
 * When evaluate_velocities has already run the position stage of this state (the end of the last communication
 * step), the step skips it: the same operations as mj_step (checks, forward dynamics, checkAcc, integrator), so
 * the same numbers, with the position stage (kinematics, inertia, collision, constraints) done once instead of twice.
 * The position stage does not depend on gravity, so it can run before the inputs are known. */
static void model_step(Ehm *e, const double a[3], const double w[3]) {
    mjtNum *g = e->m->opt.gravity;
    const mjModel *m = e->m;
    mjtNum R[9], aw[3] = {a[0], a[1], a[2]};
    mju_copy4(e->seat_q, e->seat.q);
    if (e->seat.on) {
        mju_quat2Mat(R, e->seat.q);
        mju_mulMatVec3(aw, R, a);  /* the seat acceleration in world axes */
        seat_drive(e, w);
    }
    g[0] = G0[0] - aw[0];
    g[1] = G0[1] - aw[1];
    g[2] = G0[2] - aw[2];
    if (e->pos_ready && (m->opt.integrator == mjINT_IMPLICITFAST || m->opt.integrator == mjINT_IMPLICIT ||
                         m->opt.integrator == mjINT_EULER)) {
        mj_checkPos(m, e->d);
        mj_checkVel(m, e->d);
        mj_forwardSkip(m, e->d, mjSTAGE_POS, 0);
        mj_checkAcc(m, e->d);
        if (m->opt.integrator == mjINT_EULER) mj_Euler(m, e->d);
        else mj_implicit(m, e->d);
    } else {
        mj_step(e->m, e->d);
    }
    if (e->head_control) ehm_head_control_after_step(e->m, e->d, e->head_control);
    e->pos_ready = 0;
    g[0] = G0[0];
    g[1] = G0[1];
    g[2] = G0[2];
}

/* Why the state is no longer a seated person (ehm.engine.diagnostics.instability), or NULL. */
static const char *instability(Ehm *e, char *buf, size_t size) {
    const mjData *d = e->d;
    const mjtNum *pelvis = d->qpos + e->pelvis_adr;
    int i;
    if (d->warning[mjWARN_BADQACC].number > 0) return "the accelerations became infinite or NaN";
    if (d->warning[mjWARN_BADQPOS].number > 0 || d->warning[mjWARN_BADQVEL].number > 0)
        return "the state became infinite or NaN";
    for (i = 0; i < e->nq; i++) if (!isfinite(d->qpos[i])) return "the state became infinite or NaN";
    for (i = 0; i < e->nv; i++) if (!isfinite(d->qvel[i])) return "the state became infinite or NaN";
    if (e->seat.on && fabs(e->seat.pitch) > 80 * mjPI / 180) {
        snprintf(buf, size, "the seat pitch reached %.0f deg; it must stay within +-80 deg", e->seat.pitch * 180 / mjPI);
        return buf;
    }
    if (fabs(pelvis[0]) > e->diverged_m || fabs(pelvis[1]) > e->diverged_m || fabs(pelvis[2]) > e->diverged_m) {
        snprintf(buf, size, "the pelvis moved %.3g m from its seated position", mju_norm3(pelvis));
        return buf;
    }
    return NULL;
}

/* The sensors and support forces of the state a step started from (valid right after mj_step). */
static void take_sample(Ehm *e, Sample *s) {
    const mjtNum *sd = e->d->sensordata;
    int p, g, b, j;
    for (p = 0; p < e->npoints; p++) {
        const Point *pt = &e->point[p];
        mju_copy3(s->pos[p], sd + pt->pos);
        mju_copy4(s->quat[p], sd + pt->quat);
        mju_copy3(s->linvel[p], sd + pt->linvel);
        mju_copy3(s->angvel[p], sd + pt->angvel);
    }
    mju_copy4(s->seat_q, e->seat_q);
    for (g = 0; g < e->ngroups; g++) { /* force of the surfaces on the body: their contact sensors */
        for (j = 0; j < 3; j++) s->support[g][j] = 0.0;
        for (b = 0; b < e->group[g].n; b++)
            for (j = 0; j < 3; j++) s->support[g][j] += sd[e->group[g].sensor[b] + j];
    }
}

/* Velocity-stage kinematics and sensors of the current state (ehm.engine.evaluate_velocities).  It runs the whole
 * position stage (a superset of mj_kinematics and mj_comPos), which the next model step then skips. */
static void evaluate_velocities(Ehm *e) {
    mj_fwdPosition(e->m, e->d);
    mj_sensorPos(e->m, e->d);
    mj_comVel(e->m, e->d);
    mj_sensorVel(e->m, e->d);
    e->pos_ready = 1;
}

/* The outputs of one sample, as ehm.simulation.SeatedHuman reports its row: s: the step's start state, with the
 * seat's attitude R (seat -> world; identity for a static seat, whose world axes are the seat axes); end:
 * sensordata with the velocity sensors of the step's end state; a: the seat acceleration held over the step, seat
 * axes [m/s^2]; t: the sample's time [s].  Per point (15 values):
 *   a{x,y,z}_mps2        absolute acceleration over the step, R^T ((v_end - v_start) / dt + R a)
 *   {roll,pitch,yaw}_rad intrinsic z-y-x angles of q_seat^-1 q q0^-1 (rotation from the settled posture, seat axes)
 *   {x,y,z}_m            R^T (position - pivot) - (settled position - pivot)
 *   w{x,y,z}_radps       angular velocity in the segment's own axes, q^-1 w q
 *   {roll,pitch,yaw}_acc_radps2  angular acceleration over the step, R^T (w_end - w_start) / dt
 * then the force of each support group on the body R^T f{x,y,z}_N, then output_time_s. */
static void compute_outputs(Ehm *e, const Sample *s, const mjtNum *end, const double a[3], double t, double *y) {
    int p, g, j, k = 0;
    mjtNum R[9], seat_inv[4], v[3], r[3];
    mju_quat2Mat(R, s->seat_q);
    mju_negQuat(seat_inv, s->seat_q);
    for (p = 0; p < e->npoints; p++) {
        const Point *pt = &e->point[p];
        const mjtNum *q = s->quat[p];
        mjtNum rel[4], tmp[4], qinv[4], wb[3];
        mjtNum w, x, yy, z;
        /* absolute acceleration over the step in world axes (a: seat axes), then into seat axes */
        mju_mulMatVec3(r, R, a);
        for (j = 0; j < 3; j++) v[j] = (end[pt->linvel + j] - s->linvel[p][j]) / e->dt + r[j];
        mju_mulMatTVec3(r, R, v);
        for (j = 0; j < 3; j++) y[k++] = r[j];
        mju_mulQuat(tmp, seat_inv, q);  /* orientation relative to the seat, then to the settled posture */
        mju_mulQuat(rel, tmp, pt->quat0_inv);
        mju_normalize4(rel);
        w = rel[0]; x = rel[1]; yy = rel[2]; z = rel[3];
        y[k++] = atan2(2 * (w * x + yy * z), 1 - 2 * (x * x + yy * yy));
        y[k++] = asin(fmax(-1.0, fmin(1.0, 2 * (w * yy - z * x))));
        y[k++] = atan2(2 * (w * z + x * yy), 1 - 2 * (yy * yy + z * z));
        for (j = 0; j < 3; j++) v[j] = s->pos[p][j] - e->seat.pivot[j];  /* seat axes, about the pivot */
        mju_mulMatTVec3(r, R, v);
        for (j = 0; j < 3; j++) y[k++] = r[j] - (pt->pos0[j] - e->seat.pivot[j]);
        mju_negQuat(qinv, q);
        mju_normalize4(qinv);
        mju_rotVecQuat(wb, s->angvel[p], qinv);
        for (j = 0; j < 3; j++) y[k++] = wb[j];
        for (j = 0; j < 3; j++) v[j] = (end[pt->angvel + j] - s->angvel[p][j]) / e->dt;
        mju_mulMatTVec3(r, R, v);
        for (j = 0; j < 3; j++) y[k++] = r[j];
    }
    for (g = 0; g < e->ngroups; g++) {
        mju_mulMatTVec3(r, R, s->support[g]);
        for (j = 0; j < 3; j++) y[k++] = r[j];
    }
    y[k] = t;
}

typedef struct { long long n, done; const double *a, *w; const char *why; char buf[160]; } StepArgs;

/* n model steps with the seat acceleration a held; the sample of the last one into e->y (left as it was if
 * anything is not finite). */
static int steps_work(Ehm *e, void *arg) {
    StepArgs *s = arg;
    Sample sample;
    double y[EHM_N_OUTPUTS];
    int j;
    for (s->done = 0; s->done < s->n;) {
        model_step(e, s->a, s->w);
        s->done++;
        s->why = instability(e, s->buf, sizeof s->buf);
        if (s->why) return -1;
    }
    take_sample(e, &sample); /* sensors and contact forces of the last step's start state */
    evaluate_velocities(e);
    compute_outputs(e, &sample, e->d->sensordata, s->a, e->t0 + (e->steps + s->n - 1) * e->dt, y);
    for (j = 0; j < EHM_N_OUTPUTS; j++)
        if (!isfinite(y[j])) { s->why = "an output became infinite or NaN"; return -1; }
    memcpy(e->y, y, sizeof y);
    return 0;
}

/* Outputs of the start sample: the response at t0 to the inputs now (one step, then back). */
static int initial_work(Ehm *e, void *arg) {
    StepArgs *s = arg;
    int rc;
    mj_getState(e->m, e->d, e->scratch, mjSTATE_INTEGRATION);
    e->scratch_seat = e->seat;
    rc = steps_work(e, s);
    mj_setState(e->m, e->d, e->scratch, mjSTATE_INTEGRATION);
    e->seat = e->scratch_seat;
    e->pos_ready = 0;
    return rc;
}

/* 0 if the inputs can be used, else -1 and why not in msg. */
static int check_inputs(Ehm *e, char *msg, size_t size) {
    int j;
    for (j = 0; j < 3; j++) {
        if (!isfinite(e->u[j])) {
            snprintf(msg, size, "input %s is %g: seat accelerations must be finite numbers [m/s2]", ehm_variable_names[j], e->u[j]);
            return -1;
        }
        if (fabs(e->u[j]) > e->max_seat_acc) {
            snprintf(msg, size, "input %s = %g m/s2 is beyond the model's range (|a| <= %g m/s2: the person sits "
                     "unbelted on a seat, held by contact and friction only)", ehm_variable_names[j], e->u[j], e->max_seat_acc);
            return -1;
        }
    }
    for (j = 3; j < 6 && e->seat.on; j++) {
        if (!isfinite(e->u[j]) || fabs(e->u[j]) > EHM_MAX_SEAT_RATE) {
            snprintf(msg, size, "input %s = %g rad/s is not a seat angular velocity this unit takes (finite, |w| <= %g "
                     "rad/s)", ehm_variable_names[j], e->u[j], EHM_MAX_SEAT_RATE);
            return -1;
        }
    }
    for (j = 3; j < 6 && !e->seat.on; j++) {
        if (e->u[j] != 0.0) {
            snprintf(msg, size, "input %s = %g: the seat angular velocities must stay 0 (this unit runs seat translation "
                     "only; export it with 'ehm export-fmu --rotating-seat' to turn the seat)", ehm_variable_names[j], e->u[j]);
            return -1;
        }
    }
    return 0;
}

static fmi2Status run_steps(Ehm *e, long long n, int initial) {
    StepArgs s;
    double a[3] = {e->u[0], e->u[1], e->u[2]}, w[3] = {e->u[3], e->u[4], e->u[5]};
    int rc;
    s.n = n;
    s.done = 0;
    s.a = a;
    s.w = w;
    s.why = NULL;
    rc = guarded(e, initial ? initial_work : steps_work, &s);
    if (rc == 0) {
        e->outputs_valid = 1;
        return fmi2OK;
    }
    if (s.why) snprintf(e->failed, sizeof e->failed, "the simulation diverged at t = %.4f s (%s): the seat input may be "
                        "more than a seated, unbelted person withstands, or try a smaller time step than dt = %g s",
                        e->t0 + (e->steps + s.done) * e->dt, s.why, e->dt);
    if (initial) {  /* a MuJoCo error may have left initial_work before it took its state back */
        mj_setState(e->m, e->d, e->scratch, mjSTATE_INTEGRATION);
        e->pos_ready = 0;
        e->seat = e->scratch_seat;
    }
    LOG_ERROR(e, "%s; reset the unit (fmi2Reset) or instantiate it again.", e->failed);
    return fmi2Error;
}

/* ----------------------------------------------------------------------------------------- FMI functions */

#define CHECK_INSTANCE(c, fname)                                               \
    Ehm *e = (Ehm *)(c);                                                      \
    if (!e) return fmi2Error;

static fmi2Status usable(Ehm *e, const char *fname) {
    if (e->broken) {
        LOG_ERROR(e, "%s: the unit's resources are unusable (%s).", fname, e->broken);
        return fmi2Error;
    }
    return fmi2OK;
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories, const fmi2String categories[]) {
    CHECK_INSTANCE(c, "fmi2SetDebugLogging")
    (void)nCategories;
    (void)categories;
    e->logging_on = loggingOn ? 1 : 0;
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
    Ehm *e = calloc(1, sizeof(Ehm));
    (void)visible;
    if (!e) return NULL;
    if (functions) e->cb = *functions;
    snprintf(e->instance, sizeof e->instance, "%s", instanceName ? instanceName : "ehm");
    e->logging_on = loggingOn ? 1 : 0;
    if (fmuType != fmi2CoSimulation) {
        LOG_ERROR(e, "this unit is for co-simulation only (fmi2CoSimulation), not model exchange.");
        free(e);
        return NULL;
    }
    if (!fmuGUID || strcmp(fmuGUID, EHM_GUID) != 0) {
        LOG_ERROR(e, "GUID %s does not match this unit's binary (%s): the model description and binary come from "
                  "different exports.", fmuGUID ? fmuGUID : "(none)", EHM_GUID);
        free(e);
        return NULL;
    }
    if (load_resources(e, fmuResourceLocation) == 0) {
        if (guarded(e, settled_work, NULL) < 0) LOG_ERROR(e, "%s.", e->failed);
        LOG_INFO(e, "ehm seated human on MuJoCo %s: %d degrees of freedom (MuJoCo), model step %g s.",
                 mj_versionString(), e->nv, e->dt);
    }
    e->phase = PHASE_INSTANTIATED;
    return e;
}

static void free_model(Ehm *e) {
    if (e->d) mj_deleteData(e->d);
    if (e->m) mj_deleteModel(e->m);
    free(e->qpos0);
    free(e->qvel0);
    free(e->act0);
    free(e->scratch);
    free(e->broken);
}

void fmi2FreeInstance(fmi2Component c) {
    Ehm *e = (Ehm *)c;
    if (!e) return;
    free_model(e);
    free(e);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    CHECK_INSTANCE(c, "fmi2SetupExperiment")
    (void)toleranceDefined; (void)tolerance; (void)stopTimeDefined; (void)stopTime;
    if (usable(e, "fmi2SetupExperiment") != fmi2OK) return fmi2Error;
    if (e->phase != PHASE_INSTANTIATED) {
        LOG_ERROR(e, "fmi2SetupExperiment is allowed only after fmi2Instantiate or fmi2Reset.");
        return fmi2Error;
    }
    if (!isfinite(startTime)) {
        LOG_ERROR(e, "fmi2SetupExperiment: the start time %g is not a finite number.", startTime);
        return fmi2Error;
    }
    e->t0 = startTime;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    CHECK_INSTANCE(c, "fmi2EnterInitializationMode")
    if (usable(e, "fmi2EnterInitializationMode") != fmi2OK) return fmi2Error;
    if (e->phase != PHASE_INSTANTIATED) {
        LOG_ERROR(e, "fmi2EnterInitializationMode is allowed only after fmi2Instantiate or fmi2Reset.");
        return fmi2Error;
    }
    e->phase = PHASE_INITIALIZATION;
    e->outputs_valid = 0;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    char msg[EHM_MSG];
    CHECK_INSTANCE(c, "fmi2ExitInitializationMode")
    if (usable(e, "fmi2ExitInitializationMode") != fmi2OK) return fmi2Error;
    if (e->phase != PHASE_INITIALIZATION) {
        LOG_ERROR(e, "fmi2ExitInitializationMode is allowed only in initialization mode.");
        return fmi2Error;
    }
    if (check_inputs(e, msg, sizeof msg) < 0) {
        LOG_ERROR(e, "fmi2ExitInitializationMode: %s.", msg);
        return fmi2Error;
    }
    if (!e->outputs_valid && run_steps(e, 1, 1) != fmi2OK) return fmi2Error;
    e->phase = PHASE_STEPPING;
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component c) {
    CHECK_INSTANCE(c, "fmi2Terminate")
    e->phase = PHASE_TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c) {
    int j;
    CHECK_INSTANCE(c, "fmi2Reset")
    if (usable(e, "fmi2Reset") != fmi2OK) return fmi2Error;
    e->phase = PHASE_INSTANTIATED;
    e->t0 = 0.0;
    e->steps = 0;
    e->failed[0] = '\0';
    e->outputs_valid = 0;
    for (j = 0; j < EHM_N_INPUTS; j++) e->u[j] = 0.0;
    for (j = 0; j < EHM_N_OUTPUTS; j++) e->y[j] = 0.0;
    if (guarded(e, settled_work, NULL) < 0) {
        LOG_ERROR(e, "fmi2Reset: %s.", e->failed);
        return fmi2Error;
    }
    return fmi2OK;
}

static fmi2Status check_vr(Ehm *e, const char *fname, fmi2ValueReference vr) {
    if (vr >= (fmi2ValueReference)(EHM_N_INPUTS + EHM_N_OUTPUTS)) {
        LOG_ERROR(e, "%s: this unit has no Real variable with value reference %u.", fname, vr);
        return fmi2Error;
    }
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
    size_t i;
    CHECK_INSTANCE(c, "fmi2GetReal")
    if (usable(e, "fmi2GetReal") != fmi2OK) return fmi2Error;
    if (nvr && (!vr || !value)) return fmi2Error;
    for (i = 0; i < nvr; i++) {
        if (check_vr(e, "fmi2GetReal", vr[i]) != fmi2OK) return fmi2Error;
        if (vr[i] >= EHM_N_INPUTS && !e->outputs_valid) { /* in initialization mode: the start sample */
            char msg[EHM_MSG];
            if (e->phase != PHASE_INITIALIZATION) {
                LOG_ERROR(e, "fmi2GetReal: the output %s is known only from initialization on.", ehm_variable_names[vr[i]]);
                return fmi2Error;
            }
            if (check_inputs(e, msg, sizeof msg) < 0) {
                LOG_ERROR(e, "fmi2GetReal: %s.", msg);
                return fmi2Error;
            }
            if (run_steps(e, 1, 1) != fmi2OK) return fmi2Error;
        }
    }
    for (i = 0; i < nvr; i++) value[i] = vr[i] < EHM_N_INPUTS ? e->u[vr[i]] : e->y[vr[i] - EHM_N_INPUTS];
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
    size_t i;
    CHECK_INSTANCE(c, "fmi2SetReal")
    if (usable(e, "fmi2SetReal") != fmi2OK) return fmi2Error;
    if (nvr && (!vr || !value)) return fmi2Error;
    if (e->phase == PHASE_TERMINATED) {
        LOG_ERROR(e, "fmi2SetReal after fmi2Terminate: reset the unit first.");
        return fmi2Error;
    }
    for (i = 0; i < nvr; i++) {
        if (check_vr(e, "fmi2SetReal", vr[i]) != fmi2OK) return fmi2Error;
        if (vr[i] >= EHM_N_INPUTS) {
            LOG_ERROR(e, "fmi2SetReal: %s is an output; it cannot be set.", ehm_variable_names[vr[i]]);
            return fmi2Error;
        }
    }
    for (i = 0; i < nvr; i++) {
        if (e->phase == PHASE_INITIALIZATION && e->u[vr[i]] != value[i]) e->outputs_valid = 0;
        e->u[vr[i]] = value[i];
    }
    return fmi2OK;
}

static fmi2Status no_variables(Ehm *e, const char *fname, const char *type, size_t nvr) {
    if (nvr == 0) return fmi2OK;
    LOG_ERROR(e, "%s: this unit has no %s variables.", fname, type);
    return fmi2Error;
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[]) {
    CHECK_INSTANCE(c, "fmi2GetInteger")
    (void)vr; (void)value;
    return no_variables(e, "fmi2GetInteger", "Integer", nvr);
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[]) {
    CHECK_INSTANCE(c, "fmi2GetBoolean")
    (void)vr; (void)value;
    return no_variables(e, "fmi2GetBoolean", "Boolean", nvr);
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[]) {
    CHECK_INSTANCE(c, "fmi2GetString")
    (void)vr; (void)value;
    return no_variables(e, "fmi2GetString", "String", nvr);
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[]) {
    CHECK_INSTANCE(c, "fmi2SetInteger")
    (void)vr; (void)value;
    return no_variables(e, "fmi2SetInteger", "Integer", nvr);
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[]) {
    CHECK_INSTANCE(c, "fmi2SetBoolean")
    (void)vr; (void)value;
    return no_variables(e, "fmi2SetBoolean", "Boolean", nvr);
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[]) {
    CHECK_INSTANCE(c, "fmi2SetString")
    (void)vr; (void)value;
    return no_variables(e, "fmi2SetString", "String", nvr);
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    char msg[EHM_MSG];
    double own, ratio;
    long long n;
    fmi2Status status;
    CHECK_INSTANCE(c, "fmi2DoStep")
    (void)noSetFMUStatePriorToCurrentPoint;
    if (usable(e, "fmi2DoStep") != fmi2OK) return fmi2Error;
    if (e->phase != PHASE_STEPPING) {
        LOG_ERROR(e, "fmi2DoStep is allowed only after fmi2ExitInitializationMode and before fmi2Terminate.");
        return fmi2Error;
    }
    if (e->failed[0]) {
        LOG_ERROR(e, "fmi2DoStep: the model cannot go on (%s); reset the unit (fmi2Reset) or instantiate it again.", e->failed);
        return fmi2Error;
    }
    own = e->t0 + e->steps * e->dt;
    /* a host's own clock may carry round-off (t += h): a thousandth of a model step, plus 1e-9 relative */
    if (!(fabs(currentCommunicationPoint - own) <= 1e-3 * e->dt + 1e-9 * fabs(own))) {
        LOG_ERROR(e, "fmi2DoStep at t = %.9g s, but the unit is at t = %.9g s: a step must start where the last one "
                  "ended.", currentCommunicationPoint, own);
        return fmi2Error;
    }
    ratio = communicationStepSize / e->dt;
    n = (long long)floor(ratio + 0.5);
    if (!(communicationStepSize > 0) || n < 1 || fabs(ratio - (double)n) > 1e-6 * (double)n) {
        LOG_ERROR(e, "fmi2DoStep: the communication step %.9g s is not a positive whole multiple of the model step %g s.",
                  communicationStepSize, e->dt);
        return fmi2Error;
    }
    if (check_inputs(e, msg, sizeof msg) < 0) {
        LOG_DISCARD(e, "fmi2DoStep at t = %.9g s refused, the unit stays there: %s.", own, msg);
        return fmi2Discard;
    }
    status = run_steps(e, n, 0);
    if (status == fmi2OK) e->steps += n;
    return status;
}

fmi2Status fmi2CancelStep(fmi2Component c) {
    CHECK_INSTANCE(c, "fmi2CancelStep")
    LOG_ERROR(e, "fmi2CancelStep: this unit steps synchronously; there is nothing to cancel.");
    return fmi2Error;
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    CHECK_INSTANCE(c, "fmi2SetRealInputDerivatives")
    (void)vr; (void)nvr; (void)order; (void)value;
    LOG_ERROR(e, "fmi2SetRealInputDerivatives: this unit holds its inputs over a step (canInterpolateInputs = false).");
    return fmi2Error;
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[]) {
    CHECK_INSTANCE(c, "fmi2GetRealOutputDerivatives")
    (void)vr; (void)nvr; (void)order; (void)value;
    LOG_ERROR(e, "fmi2GetRealOutputDerivatives: this unit provides no output derivatives.");
    return fmi2Error;
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[], size_t nUnknown,
                                        const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[]) {
    CHECK_INSTANCE(c, "fmi2GetDirectionalDerivative")
    (void)vUnknown_ref; (void)nUnknown; (void)vKnown_ref; (void)nKnown; (void)dvKnown; (void)dvUnknown;
    LOG_ERROR(e, "fmi2GetDirectionalDerivative: this unit provides no directional derivatives.");
    return fmi2Error;
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    CHECK_INSTANCE(c, "fmi2GetStatus")
    if (s == fmi2DoStepStatus && value) { *value = fmi2OK; return fmi2OK; }
    return fmi2Discard;
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    CHECK_INSTANCE(c, "fmi2GetRealStatus")
    if (s == fmi2LastSuccessfulTime && value) { *value = e->t0 + e->steps * e->dt; return fmi2OK; }
    return fmi2Discard;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) {
    CHECK_INSTANCE(c, "fmi2GetIntegerStatus")
    (void)s; (void)value;
    return fmi2Discard;
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    CHECK_INSTANCE(c, "fmi2GetBooleanStatus")
    if (s == fmi2Terminated && value) { *value = e->failed[0] ? fmi2True : fmi2False; return fmi2OK; }
    return fmi2Discard;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) {
    CHECK_INSTANCE(c, "fmi2GetStringStatus")
    (void)s; (void)value;
    return fmi2Discard;
}

/* ------------------------------------------------------------------------------------------- FMU state */

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *state) {
    Snapshot *s;
    CHECK_INSTANCE(c, "fmi2GetFMUstate")
    if (usable(e, "fmi2GetFMUstate") != fmi2OK || !state) return fmi2Error;
    s = (Snapshot *)*state;
    if (!s) {
        s = calloc(1, sizeof(Snapshot));
        if (s) s->mj = calloc(e->nstate, sizeof(mjtNum));
        if (!s || !s->mj) { free(s); LOG_ERROR(e, "fmi2GetFMUstate: out of memory."); return fmi2Error; }
        s->nstate = e->nstate;
    } else if (s->nstate != e->nstate) {
        LOG_ERROR(e, "fmi2GetFMUstate: the given state belongs to another unit.");
        return fmi2Error;
    }
    mj_getState(e->m, e->d, s->mj, mjSTATE_INTEGRATION);
    s->seat = e->seat;
    s->steps = e->steps;
    s->t0 = e->t0;
    memcpy(s->u, e->u, sizeof s->u);
    memcpy(s->y, e->y, sizeof s->y);
    s->outputs_valid = e->outputs_valid;
    memcpy(s->failed, e->failed, sizeof s->failed);
    *state = s;
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state) {
    const Snapshot *s = (const Snapshot *)state;
    CHECK_INSTANCE(c, "fmi2SetFMUstate")
    if (usable(e, "fmi2SetFMUstate") != fmi2OK) return fmi2Error;
    if (!s || s->nstate != e->nstate) {
        LOG_ERROR(e, "fmi2SetFMUstate: not a state of this unit.");
        return fmi2Error;
    }
    mj_setState(e->m, e->d, s->mj, mjSTATE_INTEGRATION);
    e->pos_ready = 0;
    e->seat = s->seat;
    e->steps = s->steps;
    e->t0 = s->t0;
    memcpy(e->u, s->u, sizeof e->u);
    memcpy(e->y, s->y, sizeof e->y);
    e->outputs_valid = s->outputs_valid;
    memcpy(e->failed, s->failed, sizeof e->failed);
    return fmi2OK;
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *state) {
    CHECK_INSTANCE(c, "fmi2FreeFMUstate")
    if (state && *state) {
        Snapshot *s = (Snapshot *)*state;
        free(s->mj);
        free(s);
        *state = NULL;
    }
    return fmi2OK;
}

/* Serialized: EHM_STATE_MAGIC, nstate, steps, t0, outputs_valid, u, y, the MuJoCo state (doubles), the seat's
 * kinematic state (attitude, yaw, pitch, rates, started: 10 doubles), then the failure text (EHM_MSG bytes). */
#define EHM_SEAT_DOUBLES 10
static size_t serialized_size(int nstate) {
    return (5 + EHM_N_INPUTS + EHM_N_OUTPUTS + (size_t)nstate + EHM_SEAT_DOUBLES) * sizeof(double) + EHM_MSG;
}

static void seat_to_doubles(const Seat *st, double *v) {
    int k;
    for (k = 0; k < 4; k++) v[k] = st->q[k];
    v[4] = st->yaw; v[5] = st->pitch;
    for (k = 0; k < 3; k++) v[6 + k] = st->rates[k];
    v[9] = st->started;
}

static void seat_from_doubles(Seat *st, const double *v) {
    int k;
    for (k = 0; k < 4; k++) st->q[k] = v[k];
    st->yaw = v[4]; st->pitch = v[5];
    for (k = 0; k < 3; k++) st->rates[k] = v[6 + k];
    st->started = (int)v[9];
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state, size_t *size) {
    const Snapshot *s = (const Snapshot *)state;
    CHECK_INSTANCE(c, "fmi2SerializedFMUstateSize")
    if (!s || !size) return fmi2Error;
    *size = serialized_size(s->nstate);
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state, fmi2Byte bytes[], size_t size) {
    const Snapshot *s = (const Snapshot *)state;
    double head[5];
    char *p = (char *)bytes;
    CHECK_INSTANCE(c, "fmi2SerializeFMUstate")
    if (!s || !bytes || size != serialized_size(s->nstate)) {
        LOG_ERROR(e, "fmi2SerializeFMUstate: no state, or a buffer of the wrong size.");
        return fmi2Error;
    }
    head[0] = EHM_STATE_MAGIC; head[1] = s->nstate; head[2] = (double)s->steps; head[3] = s->t0; head[4] = s->outputs_valid;
    memcpy(p, head, sizeof head); p += sizeof head;
    memcpy(p, s->u, sizeof s->u); p += sizeof s->u;
    memcpy(p, s->y, sizeof s->y); p += sizeof s->y;
    memcpy(p, s->mj, s->nstate * sizeof(mjtNum)); p += s->nstate * sizeof(mjtNum);
    {
        double seat[EHM_SEAT_DOUBLES];
        seat_to_doubles(&s->seat, seat);
        memcpy(p, seat, sizeof seat); p += sizeof seat;
    }
    memcpy(p, s->failed, EHM_MSG);
    return fmi2OK;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte bytes[], size_t size, fmi2FMUstate *state) {
    double head[5];
    const char *p = (const char *)bytes;
    Snapshot *s;
    CHECK_INSTANCE(c, "fmi2DeSerializeFMUstate")
    if (usable(e, "fmi2DeSerializeFMUstate") != fmi2OK) return fmi2Error;
    if (!bytes || !state || size != serialized_size(e->nstate)) {
        LOG_ERROR(e, "fmi2DeSerializeFMUstate: %zu bytes are not a serialized state of this unit.", size);
        return fmi2Error;
    }
    memcpy(head, p, sizeof head); p += sizeof head;
    if (head[0] != EHM_STATE_MAGIC || head[1] != e->nstate) {
        LOG_ERROR(e, "fmi2DeSerializeFMUstate: the bytes are not a serialized state of this unit.");
        return fmi2Error;
    }
    s = (Snapshot *)*state;
    if (!s) {
        fmi2FMUstate fresh = NULL;
        if (fmi2GetFMUstate(c, &fresh) != fmi2OK) return fmi2Error;
        s = (Snapshot *)fresh;
    }
    s->nstate = e->nstate;
    s->steps = (long long)head[2];
    s->t0 = head[3];
    s->outputs_valid = (int)head[4];
    memcpy(s->u, p, sizeof s->u); p += sizeof s->u;
    memcpy(s->y, p, sizeof s->y); p += sizeof s->y;
    memcpy(s->mj, p, s->nstate * sizeof(mjtNum)); p += s->nstate * sizeof(mjtNum);
    {
        double seat[EHM_SEAT_DOUBLES];
        memcpy(seat, p, sizeof seat); p += sizeof seat;
        s->seat = e->seat;  /* the hinges and pivot are the unit's own */
        seat_from_doubles(&s->seat, seat);
    }
    memcpy(s->failed, p, EHM_MSG);
    s->failed[EHM_MSG - 1] = '\0';
    *state = s;
    return fmi2OK;
}
