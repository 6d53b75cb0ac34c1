"""How a harvest runs, the same on both rigs: which berries it tries and how often, the
run's start and end records and its exit status; the map run of the markerless worlds,
the cane survey, and the simulated harvest as a Python call."""
