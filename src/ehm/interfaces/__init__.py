"""ehm to people and other tools: the ``ehm`` command (``cli``), batch studies on Dask
(``batch``, ``cluster``), the Python FMU (``fmu``) and the native one (``fmu_native``).  The
top floor: they may import everything below, and nothing of ehm imports them."""
