"""What is computed from runs of a person: transfer-function tables (``frf``), the paper's
criterion (``criterion``), the time step's check (``convergence``), step-by-step simulation
(``stepping``), the locking study (``study``), comfort and sickness of a drive (``assessment``),
validation against the references (``validation``) and parameter identification (``fit``).  They stand
on the door (``ehm.simulation``) and everything below it; only ``ehm.interfaces`` imports them."""
