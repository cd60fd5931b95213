"""The edge of the program: what every listener does with a connection before it
reads a byte of it (see :mod:`.admission` and :mod:`.listener`)."""
