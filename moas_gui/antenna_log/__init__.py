"""The antenna log: what the station's antennas did, joined to the logger's contacts.

:mod:`.records` holds the plain records every part shares (the journal writes and
reads them, the ADIF export and the contest report take them); ``docs/antenna-log.md``
says what is recorded, where and for how long.
"""
