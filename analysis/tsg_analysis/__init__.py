"""Post-analysis of TSG-DEM runs (LIGGGHTS logs, dumps and our measurement outputs)."""
