"""The command line's shape: ``ehm`` and its subcommands, in the order ``ehm --help`` lists them."""

from __future__ import annotations

import argparse

from ... import __version__
from . import interfaces, run, transfer

#: Each subcommand's ``add_parser`` function, in the order of ``ehm --help``.
SUBCOMMANDS = (
    interfaces.add_info,
    run.add_simulate,
    run.add_demo,
    transfer.add_frf,
    transfer.add_compare,
    transfer.add_fit,
    transfer.add_plot_frf,
    transfer.add_study,
    transfer.add_validate,
    run.add_assess,
    run.add_fit_sickness,
    interfaces.add_realtime,
    interfaces.add_batch,
    interfaces.add_drive,
    interfaces.add_export_fmu,
    run.add_animate,
    transfer.add_check_step,
    interfaces.add_params,
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="ehm", description="Efficient seated human model on MuJoCo.")
    parser.add_argument("--version", action="version", version=f"ehm {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    for add in SUBCOMMANDS:
        add(sub)
    return parser
