"""Option groups that several subcommands declare alike: the person, the generated excitation, the motion file."""

from __future__ import annotations

import argparse

_KEEP_SMALL_HELP = ("keep measured curves whose peak is below 10 %% of the largest of their kind for the same seat "
                    "axis (left out of the criterion, with a warning listing them, by default)")


def _model_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--params", metavar="FILE.toml", help="parameter file (default: the shipped defaults)")
    p.add_argument("--lock", action="append", metavar="JOINT", help="lock a joint (repeat or comma-separate)")
    p.add_argument("--unlock", action="append", metavar="JOINT", help="unlock a joint, e.g. waist")
    p.add_argument("--segments", metavar="FILE.csv", help="segment table (default: the paper's Table 2)")
    p.add_argument("--joints", metavar="FILE.csv", help="joint table (default: the paper's Table 1)")
    p.add_argument("--contacts", metavar="FILE.csv", help="contact ellipsoid table (default: shipped)")
    p.add_argument("--stature", type=float, metavar="M", help="scale the person to this standing height [m]")
    p.add_argument("--mass", type=float, metavar="KG", help="scale the person to this body mass [kg]")
    p.add_argument("--sitting-height", type=float, metavar="M", help="sitting height [m] (default: in proportion)")


def _excitation_options(p: argparse.ArgumentParser, duration: float) -> None:
    p.add_argument("--duration", type=float, default=duration, help=f"simulated time [s] (default {duration:g})")
    p.add_argument("--rms", type=float, default=0.3, help="rms seat acceleration of random input [m/s^2] (default 0.3)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--band", type=float, nargs=2, default=(0.1, 12.0), metavar=("LOW_HZ", "HIGH_HZ"),
                   help="band of the random input [Hz] (default 0.1 12)")
    p.add_argument("--dt", type=float, help="time step [s] (default from the parameter file: 0.001)")


def _motion_file_options(p: argparse.ArgumentParser, required: bool, help_text: str) -> None:
    """--motion FILE and how to read it: --channel, --unit (both repeatable), --imu, --rate."""
    p.add_argument("--motion", required=required, metavar="FILE", help=help_text)
    p.add_argument("--channel", action="append", metavar="KEY=NAME",
                   help="the file's name for a channel (KEY: time, ax, ay, az, wx, wy, wz; repeat; --channel time= "
                        "for a file without time stamps; --channel wx= --channel wy= --channel wz= to leave its "
                        "angular velocities out; MDF: GROUP/NAME for a name in several groups, GROUP its index); "
                        "default: time_s, ax_mps2, ..., wx_radps, ...")
    p.add_argument("--unit", action="append", metavar="KEY=UNIT",
                   help="unit of a channel, e.g. ax=g, wx=deg/s, time=ns, or a date-time format such as "
                        "'time=%%d/%%m/%%Y %%H:%%M:%%S' (repeat; wins over a unit in the channel's name; default: the "
                        "name's unit, as in 'Accelerometer X (g)' or time_ms, else SI)")
    p.add_argument("--imu", action="store_true",
                   help="the file is an IMU at the seat: ax, ay, az its specific force (gravity included), wx, wy, wz "
                        "its gyro rates; the log must start with 1 s at rest")
    p.add_argument("--fill-gaps", action="store_true",
                   help="bridge gaps in the file's time stamps (steps over 5 median steps: a logger's dropout) with a "
                        "straight line, with a warning naming where (default: refuse them)")
    p.add_argument("--rate", type=float, metavar="HZ",
                   help="sample rate of a file without time stamps (otherwise: resample the file to this rate)")
