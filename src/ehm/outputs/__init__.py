"""What a run gives and where it goes: run results (``results``), a run's files written chunk by
chunk (``runfiles``), output folders put in place (``outdir``), DataFrames and Datasets out
(``dataframes``), figures (``plotting``), pictures and animations (``animation``) and reports
(``report``).  They take data and import the engine, ``ehm.standards`` and the ground, never a route,
the door (``ehm.simulation``) or an analysis."""
