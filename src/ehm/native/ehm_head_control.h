/* The head-in-space control after a MuJoCo step, shared by the compiled stepping loop (ehm_steps.c) and the native
 * FMU (ehm_fmu.c), so that both step exactly as ehm.engine.control.after_step does.
 *
 * Written for ehm (MIT licence).  The law's constants come in the order of ehm.engine.control.NUMERIC_FIELDS (the
 * model's numeric "ehm_head_control"); the reference up (head axes) and the line of the last N - 1 torques, oldest
 * first, live in d->userdata. */
#ifndef EHM_HEAD_CONTROL_H
#define EHM_HEAD_CONTROL_H

#include <string.h>

#include <mujoco/mujoco.h>

/* ehm.engine.control.NUMERIC_FIELDS */
enum { HC_STEPS, HC_HEAD, HC_TORSO, HC_QUAT, HC_ANGVEL, HC_KP, HC_KD, HC_KYAW };

/* After a MuJoCo step: the torque of the state it started from into the delay line, the mean of the two oldest
 * torques onto head and upper torso for the next step. */
static void ehm_head_control_after_step(const mjModel *m, mjData *d, const mjtNum *c) {
    const mjtNum *s = d->sensordata;
    const mjtNum *w = s + (int)c[HC_ANGVEL];
    mjtNum u[3], tau[3], applied[3], *line = d->userdata + 3, *head, *torso;
    int n = (int)m->nuserdata - 3, k;
    mju_rotVecQuat(u, d->userdata, s + (int)c[HC_QUAT]);
    tau[0] = c[HC_KP] * u[1] - c[HC_KD] * w[0];
    tau[1] = -c[HC_KP] * u[0] - c[HC_KD] * w[1];
    tau[2] = -c[HC_KYAW] * w[2];
    for (k = 0; k < 3; k++) applied[k] = 0.5 * (line[k] + (n > 3 ? line[3 + k] : tau[k]));
    memmove(line, line + 3, (size_t)(n - 3) * sizeof(mjtNum));
    for (k = 0; k < 3; k++) line[n - 3 + k] = tau[k];
    head = d->xfrc_applied + 6 * (int)c[HC_HEAD] + 3;
    torso = d->xfrc_applied + 6 * (int)c[HC_TORSO] + 3;
    for (k = 0; k < 3; k++) {
        head[k] = applied[k];
        torso[k] = -applied[k];
    }
}

#endif
