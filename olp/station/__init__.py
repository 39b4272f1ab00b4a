"""Stations: the robot, its tools and frames. See :mod:`olp.station.loader` for the YAML form."""
