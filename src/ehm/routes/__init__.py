"""The routes: how a drive runs through the person, each a room of its own below the door (:class:`ehm.SeatedHuman`).

:mod:`~ehm.routes.nonlinear` steps the MuJoCo model chunk by chunk; :mod:`~ehm.routes.linear` runs the person
linearised at rest; :mod:`~ehm.routes.hybrid` checks the linear route against the nonlinear one where a contact
reaches its friction limit and, as the hybrid route, runs the nonlinear model there; :mod:`~ehm.routes.poses`
gives the linear pieces' poses for pictures; :mod:`~ehm.routes.parallel` runs the nonlinear route in segments on
several processes or a Dask cluster.  Every route takes the person as built (:class:`~ehm.routes.built.BuiltPerson`,
which the door creates and hands down) and the drive as data, and calls nothing above it;
:mod:`~ehm.routes.registry` names them (``"nonlinear"``, ``"linear"``, ``"hybrid"``/``"auto"``, ``"parallel"``)
for the door and :func:`ehm.assess`.
"""
