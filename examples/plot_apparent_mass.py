"""
Apparent mass of the default person
===================================

The apparent mass (ISO 5982) is the force of the supports on the body per unit seat acceleration, in kg.
:func:`ehm.linear_frf` returns it next to the transmissibilities: ``("z", "seat_pan", "z")`` is the seat
pan with its cushion bolsters, ``("z", "support", "z")`` the seat pan, backrest and floor together.
At low frequency the body moves with the seat and the supports together carry about its mass.
"""

import matplotlib.pyplot as plt

import ehm

human = ehm.SeatedHuman()
table = ehm.linear_frf(human, axis="z")
print(f"body mass {human.info()['mass_kg']:.1f} kg")

fig, ax = plt.subplots(figsize=(6, 3.5))
for support, label in [("support", "all supports"), ("seat_pan", "seat pan")]:
    curve = table.curve("z", support, "z")
    f, m = curve.peak()
    print(f"{label}: {curve.gain[0]:.1f} kg at {curve.freq_hz[0]:.1f} Hz, peak {m:.1f} kg at {f:.2f} Hz")
    ax.plot(curve.freq_hz, curve.gain, label=label)
ax.set_xlabel("frequency [Hz]")
ax.set_ylabel("vertical apparent mass [kg]")
ax.legend()
fig.tight_layout()
