"""
Results in pandas, and what a notebook shows
============================================

Every result of ehm shows itself in a notebook as a short table (what was run, the headline figures) and
turns into a pandas DataFrame with ``to_dataframe()``: tidy (long) where the values share a unit, units in
the column names, the run's description and route in ``DataFrame.attrs``. Here on the linear route, which
runs a 20 s drive in milliseconds.
"""

import matplotlib.pyplot as plt

import ehm

human = ehm.SeatedHuman()  # the default person, settled into the seat
motion = ehm.random_vibration("z", duration_s=20.0, rms_mps2=0.5, seed=0)
run = human.simulate(motion, method="linear")
run  # in a notebook (and on this page): what was run, and the rms accelerations

# %%
# The time series, long: one row per sample, location and axis, a column per quantity (``acc_mps2``,
# ``disp_m``, ``rot_rad``, ``angacc_radps2``, ``force_N``). ``wide=True`` gives the columns of
# ``timeseries.csv`` instead, and ``run.to_xarray()`` the points x axes x time arrays.

df = run.to_dataframe()
print(df.attrs["route"], "|", df.attrs["description"])
head = df[(df.location == "head") & (df.time_s < 5.0)]
ax = head.pivot(index="time_s", columns="axis", values="acc_mps2").plot(figsize=(6, 3))
ax.set_ylabel("head acceleration [m/s²]")
plt.tight_layout()

# %%
# The same drive assessed (ISO 2631-1 comfort and motion sickness): its table has one row per location,
# axis and metric, with the value's unit beside it.

assessment = ehm.assess(motion, human, method="linear")
assessment

# %%

figures = assessment.to_dataframe()
figures[figures.metric == "a_w"].pivot(index="location", columns="axis", values="value")

# %%
# Transfer functions: the long table of ``FrfTable.to_csv``, with the gain's unit on every row.

table = ehm.linear_frf(human, axis="z")
frf = table.to_dataframe()
fig, ax = plt.subplots(figsize=(6, 3))
for point, curve in frf[(frf.dof == "z") & frf.point.isin(["pelvis", "trunk", "head"])].groupby(
        "point", observed=True):
    ax.plot(curve.freq_hz, curve.gain, label=point)
ax.set_xlabel("frequency [Hz]")
ax.set_ylabel("vertical transmissibility")
ax.legend()
fig.tight_layout()
table
