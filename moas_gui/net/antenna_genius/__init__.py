"""The 4O3A Antenna Genius API, served by a MOAS station (docs/antenna-genius.md).

:mod:`.codec` reads and writes the protocol's lines (sans-IO), :mod:`.mapping` says
what its ports, antennas and bands stand for, :mod:`.access` who may use it,
:mod:`.discovery` announces it on the station's networks and :mod:`.server` serves it.
"""
