"""
Seat-to-head transmissibility, two ways
=======================================

Shake the default person vertically with 30 s of random vibration (0.3 m/s² rms, 0.1-12 Hz), estimate
the seat-to-head transfer function from the two time histories with :func:`ehm.h1_estimate`, and lay it
over the exact response of the linearised person (:func:`ehm.linear_frf`). At this level the contacts
stay closed and stuck, so the two routes should agree on the same-axis path.
"""

import matplotlib.pyplot as plt

import ehm

human = ehm.SeatedHuman()  # the default person, settled into the seat
motion = ehm.random_vibration("z", duration_s=30.0, rms_mps2=0.3, seed=0)
run = human.simulate(motion, method="nonlinear")  # the full model, against the linearised one below

head = run.point("head")
estimate = ehm.h1_estimate(run.seat_acc_mps2[:, 2], head.acc_mps2[:, 2], fs_hz=1 / run.dt_s)
exact = ehm.linear_frf(human, axis="z").curve("z", "head", "z")

f_peak, g_peak = estimate.peak()
print(f"H1 estimate: peak {g_peak:.2f} at {f_peak:.2f} Hz")
f_peak, g_peak = exact.peak()
print(f"linear route: peak {g_peak:.2f} at {f_peak:.2f} Hz")

# %%
# The estimate is noisier below 1 Hz, where 30 s of record holds few cycles; the ISO 2631-1 range of
# seated vibration comfort starts at 0.5 Hz.

fig, (ax_gain, ax_coh) = plt.subplots(2, 1, sharex=True, figsize=(6, 5), height_ratios=[3, 1])
ax_gain.plot(estimate.freq_hz, estimate.gain, label="H1 estimate (30 s run)")
ax_gain.plot(exact.freq_hz, exact.gain, "--", label="linearised model (exact)")
ax_gain.set_ylabel("head z / seat z [(m/s²)/(m/s²)]")
ax_gain.legend()
ax_coh.plot(estimate.freq_hz, estimate.coherence)
ax_coh.set_ylabel("coherence")
ax_coh.set_xlabel("frequency [Hz]")
ax_coh.set_xlim(0.5, 12)
ax_coh.set_ylim(0, 1.05)
fig.tight_layout()
