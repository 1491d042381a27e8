"""Outside data in: seat motions and vehicle logs from files and DataFrames, in the logger's names and units.

The one door for outside data formats.  :func:`~ehm.read_motion` reads

* ``.csv`` / ``.txt`` text tables (pandas; the dialect is sniffed: separator ``,`` ``;`` tab ``|`` or
  blanks, decimal comma, byte-order mark (UTF-8, UTF-16, UTF-32; ``encoding`` names another, e.g. cp1252),
  ``#`` comment lines; the first comment line before the header describes the motion);
* ``.parquet`` tables (pyarrow; extra ``parquet``);
* MATLAB ``.mat`` files, v5 (``scipy.io``) and v7.3 (HDF5, ``pymatreader``; extra ``logs``): variables,
  struct fields as ``data.acc_x`` and matrix columns as ``name[2]`` (counting from 0);
* ASAM MDF ``.mf4`` / ``.mdf`` logs (asammdf; extra ``logs``): each channel's own time stamps and unit;
* a pandas ``DataFrame`` (the time channel may also be its index: seconds, or a datetime/timedelta index).

``channels`` maps the keys ``time, ax, ay, az, wx, wy, wz`` to the source's own names (defaults: the
motion CSV columns ``time_s, ax_mps2, ay_mps2, az_mps2, wx_radps, wy_radps, wz_radps``; the angular
velocities are optional, all three or none).  Units come from ``units`` (key -> unit string such as
``"g"``, ``"m/s^2"``, ``"deg/s"``, ``"rad/s"``, ``"ms"``), else from the file (MDF channel units), else
from the channel's name, else SI; they are converted with pint (``g`` or ``G`` of an acceleration is
standard gravity, 9.80665 m/s^2, ``mg`` a thousandth of it).  A name carries its unit at its end in brackets
(``acc_x [g]``), in parentheses (``Accelerometer X (g)``, ``accelerometerAccelerationX(G)``, ``Time (ms)``),
after " in " (``Acceleration in m/s^2``), or as its last word (``acc_x_g``, ``gyro_x_dps``, ``Gyro X °/s``,
``time_ns``, and ehm's own ``_mps2``, ``_radps``, ``_s``).

The time axis starts at 0 at the first sample.  Time stamps may be numbers in s, ms, µs or ns from any
origin (a logger's clock, Unix time, uptime since boot), date-time values, or date-time strings (ISO 8601,
``25/11/2026 14:03:07.123``, ``11/25/2026 ...``, ``25.11.2026 ...``; any other with its strftime format as
the time's unit).  A count's unit nobody gives is inferred only where nothing else fits (whole numbers under
a name counting ns, ms or µs inside a word, ``uptimeNanos``; Unix time in ns), else seconds are taken.
After conversion the values must fit their units: a median time step (of ``time`` or ``dt``) outside 10 µs -
0.5 s whatever gave its unit (10 s for a table of fewer than 1000 rows said to be in seconds: ``time_s``, ``--unit
time=s``), or of 10 kHz or faster in a log of under a second, is refused naming the ``--unit`` that fits; an
acceleration whose norm is gravity in g, or over 5 g for half the log, and angular rates beyond a vehicle's in
rad/s are refused in one sentence naming the ``--unit`` (``units``) that fixes it where the unit was taken for want
of one, and warned about where the name or the file gave it.  A True/False column, or a mostly empty 0/1 one (a
flag), is refused as a channel of measured values.

With ``imu=True`` the accelerations are an IMU's specific force
(gravity included, sensor axes) and the rates its gyro rates: :func:`ehm.from_imu` turns them into
the seat's motion.

Layouts that used to need a script read with options (``ehm.inputs.readers.layout``): ``columns`` names the columns
of a text file without a header row; ``channels={"dt": NAME}`` takes a column of the time since the previous row;
``"-NAME"`` flips a channel's sign; ``mounting`` turns the sensor's axes into the seat's; ``gyro`` joins a gyro
logged in a file of its own; ``start_s``/``end_s`` cut the log before any check.  Held samples (a slow sensor
written at a higher rate: every acceleration channel repeating in regular runs) are dropped (``drop_held=False``
keeps them), and irregular time stamps resampled, each with one note.

Time stamps must keep one sample rate (a log whose rate changes part way is refused, naming where and the
two rates: resampled as one rate it would alias) and have no gaps longer than ``GAP_STEPS`` median steps
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
