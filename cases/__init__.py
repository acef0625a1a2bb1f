"""Case tools of TSG-DEM: runner, free-space fill and feed, PSD, sweep, and the one lmp launcher."""
