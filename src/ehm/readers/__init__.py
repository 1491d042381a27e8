"""Outside data in: seat motions and vehicle logs from files and DataFrames, in the logger's names and units.

The one door for outside data formats.  :func:`read_motion` reads

* ``.csv`` / ``.txt`` text tables (pandas; the dialect is sniffed: separator ``,`` ``;`` tab ``|`` or
  blanks, decimal comma, byte-order mark, ``#`` comment lines; the first comment line before the header
  describes the motion);
* ``.parquet`` tables (pyarrow; extra ``parquet``);
* MATLAB ``.mat`` files, v5 (``scipy.io``) and v7.3 (HDF5, ``pymatreader``; extra ``logs``): variables,
  struct fields as ``data.acc_x`` and matrix columns as ``name[2]`` (counting from 0);
* ASAM MDF ``.mf4`` / ``.mdf`` logs (asammdf; extra ``logs``): each channel's own time stamps and unit;
* a pandas ``DataFrame`` (the time channel may also be its index: seconds, or a datetime/timedelta index).

``channels`` maps the keys ``time, ax, ay, az, wx, wy, wz`` to the source's own names (defaults: the
motion CSV columns ``time_s, ax_mps2, ay_mps2, az_mps2, wx_radps, wy_radps, wz_radps``; the angular
velocities are optional, all three or none).  Units come from ``units`` (key -> unit string such as
``"g"``, ``"m/s^2"``, ``"deg/s"``, ``"rad/s"``, ``"ms"``), else from the file (MDF channel units, a
``[unit]`` at the end of a column name), else SI; they are converted with pint (``g`` of an acceleration
is standard gravity, 9.80665 m/s^2).  With ``imu=True`` the accelerations are an IMU's specific force
(gravity included, sensor axes) and the rates its gyro rates: :func:`ehm.imu.from_imu` turns them into
the seat's motion.

Layouts that used to need a script read with options (:mod:`ehm.readers.layout`): ``columns`` names the columns
of a text file without a header row; ``channels={"dt": NAME}`` takes a column of the time since the previous row;
``"-NAME"`` flips a channel's sign; ``mounting`` turns the sensor's axes into the seat's; ``gyro`` joins a gyro
logged in a file of its own; ``start_s``/``end_s`` cut the log before any check.  Held samples (a slow sensor
written at a higher rate) are dropped, and irregular time stamps resampled, each with one note.

Time stamps must keep one sample rate (a log whose rate changes part way is refused, naming where and the
two rates: resampled as one rate it would alias) and have no gaps longer than :data:`GAP_STEPS` median steps
(refused, or bridged with a straight line and a warning with ``fill_gaps=True``, ``--fill-gaps``).

Bad input ends in one sentence naming the file, channel, line or row and the value; a channel that is not
in the source is named together with the channels that are.
"""

from __future__ import annotations

from .channels import CHANNEL_KEYS, DEFAULT_CHANNELS, SI_UNITS, parse_assignments
from .checks import GAP_STEPS, MIN_OVERLAP, RATE_CHANGE_RATIO, RATE_WINDOW
from .layout import HELD_RUN_MAX, HELD_SHARE, mounting_rotation, parse_columns
from .read import load_motion_csv, read_motion

__all__ = ["CHANNEL_KEYS", "DEFAULT_CHANNELS", "GAP_STEPS", "HELD_RUN_MAX", "HELD_SHARE", "MIN_OVERLAP",
           "RATE_CHANGE_RATIO", "RATE_WINDOW", "SI_UNITS", "load_motion_csv", "mounting_rotation", "parse_assignments",
           "parse_columns", "read_motion"]
