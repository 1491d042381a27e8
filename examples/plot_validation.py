"""
The default person against the standards
========================================

:func:`ehm.validate` evaluates a person against every reference of :mod:`ehm.standards.references`: ISO 2631-5's
seat-to-lumbar transfer function, Fairley & Griffin's one-mass fit to the measured apparent mass of 60
seated people, the whole-body mode near 5 Hz, the seat-to-head ranges reported for seated people, and the
paper's joint-locking findings. Each check gives the model's figure, the band, and whether it passes.

Each band is graded only where its source applies: the person is evaluated without a back support, sitting
erect (the references' condition: every band applies there), and on its own seat (the paper's seat with a high
back support: the bands of every seat, and the paper's locking findings). ``ehm validate --all`` evaluates every
posture on every back support (:ref:`validate-all`). The table and the figures below are computed when this site
is built, from the parameters this version of ehm ships: they are what ``ehm validate`` prints and draws today.
"""

import ehm
from ehm.outputs.plotting import plot_validation

validation = ehm.validate()  # the default person, in the references' condition and on its own seat
print(validation.format_table())
print("every check passes" if validation.passed else
      f"not passing: {', '.join(dict.fromkeys(c.name for c in validation.failed))}")

# %%
# Vertical input
# --------------
# (a) the seat-to-lumbar gain against ISO 2631-5:2018's Formula 1, with the band of ±0.20 over 1-12 Hz
# and its peak's window; (b) the apparent mass of all supports over its 0.5 Hz value against the one-mass
# fit (no frame mass to half the body on the frame, the region between shaded), with the peak's box and
# the upper limits at 10 and 15-20 Hz; (c) seat-to-pelvis and seat-to-head gains with the head's band and
# the pelvis peak's limit. Solid lines: erect without back support; dashed: the person's own seat.
# A dot marks where a check passes, a cross where it fails.

fig_z = plot_validation(validation, "z")

# %%
# Fore-aft and lateral input
# --------------------------
# The head's fore-aft and lateral peaks should lie below 3 Hz, and their gains stay at most 3, on any seat.

fig_x = plot_validation(validation, "x")
fig_y = plot_validation(validation, "y")
