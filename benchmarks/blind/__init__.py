"""The blind benchmark of ``hunting diagnose``: an independent data generator (no code shared with
hunting's synthetic data or integrators), a runner that judges the diagnosis and a sparse-
regression peer on it, and its tests' subset. See benchmarks/blind/README.md."""
