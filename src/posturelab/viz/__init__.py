"""Figures (:mod:`.plots`, functions that draw on a matplotlib Axes) and stick-figure
animation (:mod:`.animation`). Importing either loads matplotlib."""
