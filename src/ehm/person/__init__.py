"""The person: who sits where, as one value.

:class:`ehm.Person` holds the parameters, body tables and size, posture, back support, head control, locked joints
and time step of one seated person; every entry point (``SeatedHuman``, ``Simulator``, ``assess``, the transfer
functions, ``check_step``, ``validate``, ``export_fmu``, batch studies, the command line) takes it, and
:meth:`ehm.Person.resolved` hands the model builder what it needs as plain data.
"""

from .person import Person

__all__ = ["Person"]
