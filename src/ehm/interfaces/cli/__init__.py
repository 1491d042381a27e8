"""The ``ehm`` command: a thin layer over the library.

Every subcommand maps onto library calls; problems with input end in one sentence on stderr and exit
code 2, never a traceback.

One module per idea: ``options`` (option groups several subcommands share), ``common`` (what they make of
their arguments), ``progress`` (the progress line), ``run`` (simulate, demo, assess, animate), ``transfer``
(frf, compare, fit, plot-frf, check-step, study), ``interfaces`` (info, params, drive, realtime, batch,
export-fmu), ``parser`` (``build_parser``) and ``entry`` (``main`` and its error handling).
"""

from .entry import EXIT_ERROR, Terminated, main
from .interfaces import cmd_batch, cmd_drive, cmd_export_fmu, cmd_info, cmd_params, cmd_realtime
from .parser import build_parser
from .run import DEMO_MIN_SEGMENTS, DEMO_SEGMENT_S, cmd_animate, cmd_assess, cmd_demo, cmd_simulate
from .transfer import (
                       EXIT_NOT_IDENTIFIED,
                       cmd_check_step,
                       cmd_compare,
                       cmd_fit,
                       cmd_frf,
                       cmd_plot_frf,
                       cmd_study_locking,
)

__all__ = [
    "main", "build_parser", "Terminated", "EXIT_ERROR", "EXIT_NOT_IDENTIFIED", "DEMO_SEGMENT_S",
    "DEMO_MIN_SEGMENTS", "cmd_info", "cmd_simulate", "cmd_demo", "cmd_frf", "cmd_compare", "cmd_fit",
    "cmd_plot_frf", "cmd_study_locking", "cmd_assess", "cmd_realtime", "cmd_batch", "cmd_drive",
    "cmd_export_fmu", "cmd_animate", "cmd_check_step", "cmd_params",
]
