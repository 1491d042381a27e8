"""The person as data: parameter files (``params``), the body tables (``tables``), named
postures (``posture``), the back supports and where their pads sit (``supports``), and the time step's
known error and range (``timestep``).  Nothing here builds or runs a model; these modules import only
``ehm.errors`` and ``ehm.files``, and the engine is built from them."""
