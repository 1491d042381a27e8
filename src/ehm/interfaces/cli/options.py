"""Option groups that several subcommands declare alike: the person, the generated excitation, the motion file."""

from __future__ import annotations

import argparse

KEEP_SMALL_HELP = ("keep measured curves whose peak is below 10 %% of the largest of their kind for the same seat "
                    "axis (left out of the criterion, with a warning listing them, by default)")


def seating_options(p: argparse.ArgumentParser) -> None:
    """--posture and --back-support: how the person sits (ehm.body.posture, ehm.body.supports)."""
    p.add_argument("--posture", metavar="NAME",
                   help="reference posture: erect, slouched, or one the parameter file defines in [postures.NAME] "
                        "(default: the parameter file's posture.name, erect)")
    p.add_argument("--back-support", metavar="KIND",
                   help="the seat's back support: none, low (one pad at the posterior superior iliac spine), high "
                        "(also one at the scapula: the paper's seat) or full (a car backrest) (default: the parameter "
                        "file's seat.back_support, high)")
    p.add_argument("--head-control", action="store_true",
                   help="head-in-space control on top of the joint PID: neck torques from the head's tilt and angular "
                        "velocity in space, delayed (gains: the parameter file's [head_control]; docs/model.md)")
    p.add_argument("--head-control-gains", metavar="KEY=VALUE,...",
                   help="head-in-space control with these gains (implies --head-control), e.g. "
                        "tilt_stiffness_Nm_per_rad=30,tilt_damping_Nms_per_rad=2,yaw_damping_Nms_per_rad=1,"
                        "delay_s=0.03")
    p.add_argument("--vibration-rms", type=float, metavar="RMS",
                   help="the seat's vibration level the person is built at [m/s^2 rms]: the soft tissue and muscle "
                        "the parameter file's [level] names soften as the vibration grows (docs/model.md, 'Vibration "
                        "magnitude') (default: the drive's own level, its rms above 0.5 Hz; without a drive the "
                        "file's reference level, 1 m/s^2)")


def model_options(p: argparse.ArgumentParser) -> None:
    """--params, the seating options, --lock and the body tables: the person a command models."""
    p.add_argument("--params", metavar="FILE.toml", help="parameter file (default: the shipped defaults)")
    seating_options(p)
    p.add_argument("--lock", action="append", metavar="JOINT", help="lock a joint (repeat or comma-separate)")
    p.add_argument("--unlock", action="append", metavar="JOINT", help="unlock a joint, e.g. waist")
    p.add_argument("--segments", metavar="FILE.csv", help="segment table (default: the paper's Table 2)")
    p.add_argument("--joints", metavar="FILE.csv", help="joint table (default: the paper's Table 1)")
    p.add_argument("--contacts", metavar="FILE.csv", help="contact ellipsoid table (default: shipped)")
    size_options(p)


def size_options(p: argparse.ArgumentParser) -> None:
    """--stature, --mass, --sitting-height: an individual body size (ehm.person.scaling; read by
    common.size_from_args)."""
    p.add_argument("--stature", type=float, metavar="M", help="scale the person to this standing height [m]")
    p.add_argument("--mass", type=float, metavar="KG", help="scale the person to this body mass [kg]")
    p.add_argument("--sitting-height", type=float, metavar="M", help="sitting height [m] (default: in proportion)")


def excitation_options(p: argparse.ArgumentParser, duration: float) -> None:
    """--duration (default ``duration``), --rms, --seed: the generated seat motion of a command."""
    p.add_argument("--duration", type=float, default=duration, help=f"simulated time [s] (default {duration:g})")
    p.add_argument("--rms", type=float, default=0.3, help="rms seat acceleration of random input [m/s^2] (default 0.3)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--band", type=float, nargs=2, default=(0.1, 12.0), metavar=("LOW_HZ", "HIGH_HZ"),
                   help="band of the random input [Hz] (default 0.1 12)")
    p.add_argument("--dt", type=float, help="time step [s] (default: the parameter file's 0.001, or the posture's "
                                            "own converged step: slouched 0.0005)")


def motion_file_options(p: argparse.ArgumentParser, required: bool, help_text: str) -> None:
    """--motion FILE and how to read it: --channel, --unit (both repeatable), --encoding, --columns, --gyro,
    --mounting, --start, --end, --keep-handling, --imu, --drop-held, --fill-gaps, --rate."""
    p.add_argument("--motion", required=required, metavar="FILE", help=help_text)
    p.add_argument("--channel", action="append", metavar="KEY=NAME",
                   help="the file's name for a channel (KEY: time, ax, ay, az, wx, wy, wz, dt; repeat; --channel time= "
                        "for a file without time stamps; --channel wx= --channel wy= --channel wz= to leave its "
                        "angular velocities out; dt=NAME: a column of the time since the previous row, instead of "
                        "time; KEY=-NAME: the column with its sign flipped; MDF: GROUP/NAME for a name in several "
                        "groups, GROUP its index); default: time_s, ax_mps2, ..., wx_radps, ...")
    p.add_argument("--unit", action="append", metavar="KEY=UNIT",
                   help="unit of a channel, e.g. ax=g, wx=deg/s, time=ns, dt=ms, or a date-time format such as "
                        "'time=%%d/%%m/%%Y %%H:%%M:%%S' (repeat; wins over a unit in the channel's name; default: the "
                        "name's unit, as in 'Accelerometer X (g)', time_ms or delay_ms, else SI; a time step outside "
                        "2 Hz-100 kHz in the unit taken, given or not, is refused)")
    p.add_argument("--encoding", metavar="NAME",
                   help="text encoding of a text file, e.g. cp1252 for a Windows export (default: from its byte-order "
                        "mark, UTF-16 found without one, else UTF-8)")
    p.add_argument("--columns", metavar="NAME,NAME,...",
                   help="names of the columns of a text file without a header row, in order (e.g. x,y,z,delay_ms); "
                        "then name its channels with --channel (a file whose first row is numbers needs them)")
    p.add_argument("--gyro", metavar="FILE",
                   help="a gyro logged in a file of its own, with its own time stamps: wx, wy, wz (and the time, "
                        "named by the same --channel and --unit) come from it, joined onto the accelerometer's time "
                        "stamps over the span both cover (at least 90 %% of it)")
    p.add_argument("--mounting", metavar="ROLL,PITCH,YAW",
                   help="the sensor's mounting in degrees: its axes are the seat's (x forward, y left, z up) turned "
                        "by YAW about z, then PITCH about y, then ROLL about x; accelerations and angular velocities "
                        "are turned into seat axes (e.g. 0,0,90: the sensor's x points left; a first angle below 0 "
                        "with =: --mounting=-90,0,0)")
    p.add_argument("--start", type=float, metavar="S",
                   help="read the log from S seconds after its first sample (cut before any check: e.g. a phone "
                        "being put in place)")
    p.add_argument("--end", type=float, metavar="S", help="read the log up to S seconds after its first sample")
    p.add_argument("--keep-handling", action="store_true",
                   help="keep a handled start and end (by default, in a log with gravity that is not --imu or "
                        "--frame earth, the first or last seconds where the logger is turned against gravity by a "
                        "hand, at most 20 %% of the log at either end, are left out with a note)")
    p.add_argument("--imu", action="store_true",
                   help="the file is an IMU at the seat: ax, ay, az its specific force (gravity included), wx, wy, wz "
                        "its gyro rates (--channel wx= --channel wy= --channel wz= for an accelerometer-only log); "
                        "attitude from a gravity-aided filter, gyro bias from rests of 2 s or more anywhere in the log")
    p.add_argument("--rest", type=float, metavar="S",
                   help="--imu: the shortest rest whose gyro rate is taken as bias [s] (default 2)")
    p.add_argument("--max-tilt", type=float, metavar="DEG",
                   help="--imu: the largest seat roll or pitch accepted [deg] (default 45)")
    p.add_argument("--drop-held", action=argparse.BooleanOptionalAction, default=True,
                   help="drop held samples (a slow sensor written at a higher rate: all acceleration channels "
                        "repeating together in regular runs), with a note (default); --no-drop-held keeps every row")
    p.add_argument("--fill-gaps", action="store_true",
                   help="bridge gaps in the file's time stamps (steps over 5 median steps: a logger's dropout) with a "
                        "straight line, with a warning naming where (default: refuse them)")
    p.add_argument("--gravity", choices=("auto", "included", "removed"), default="auto",
                   help="gravity in the file's accelerations (not --imu): included: level the log (tilt from its "
                        "quietest 5 s near 1 g, g removed; refused without gravity); removed: take it as it is (a "
                        "mean near 1 g, or a mean z above 2 m/s^2, is refused); auto (default): level it, with a "
                        "warning, when the quietest 5 s have a mean (its norm or its z) within 10 %% of g; otherwise "
                        "take it as it is, but refuse a log whose mean z is above 2 m/s^2 (an offset), and one of 5 s "
                        "or longer whose quietest 5 s have a mean of half a g or more")
    p.add_argument("--frame", choices=("seat", "earth"), default="seat",
                   help="axes of the file's accelerations: seat (x forward, y left, z up; default) or earth (x east, "
                        "y north, z up, as a phone app turns them): read as they are, with a note on what the "
                        "missing heading leaves out")
    p.add_argument("--rate", type=float, metavar="HZ",
                   help="sample rate of a file without time stamps (otherwise: resample the file to this rate, with "
                        "a warning when that loses 1 %% or more of the Wk or Wd band's power); 2 Hz to 100 kHz")


def progress_options(p: argparse.ArgumentParser) -> None:
    """--quiet: the commands that show progress on stderr (ehm.interfaces.cli.progress)."""
    p.add_argument("-q", "--quiet", action="store_true",
                   help="show no progress on stderr (by default a bar on a terminal; on a pipe or a file a line "
                        "every 10 s at most)")


def parallel_options(p: argparse.ArgumentParser) -> None:
    """--workers, --scheduler, --lead-in: the nonlinear route in segments on several cores (ehm.routes.parallel)."""
    p.add_argument("--workers", type=int, metavar="N",
                   help="run the nonlinear route in N segments on N local processes, each after a lead-in (default: a "
                        "drive of 3 minutes or more that runs on the nonlinear model from its start goes in segments "
                        "on the machine's cores, up to 8; anything else runs in this process; --workers 1: always one "
                        "process; at most what the machine holds: its cores, and its memory at about 0.4 GB per "
                        "worker, with a warning); see 'Long runs on several cores' in the user guide for how close to "
                        "the continuous run this comes")
    p.add_argument("--scheduler", metavar="tcp://HOST:PORT",
                   help="run the segments on this Dask scheduler's workers instead (one segment per worker)")
    p.add_argument("--lead-in", type=float, metavar="S",
                   help="lead-in of each segment but the first [s] (default: ehm.routes.parallel.DEFAULT_LEAD_IN_S)")
