"""Rotator controllers on serial ports: one sans-IO codec and one emulator model per model.

``models.find_model("4")`` (or a name, ``"Yaesu"``) gives a :class:`~.models.Model`:
its facts (``info``), a new codec (``codec()``) and a new emulator
(``make_emulator()``).  ``pty_host.EmulatorHost`` serves emulators on
pseudo-terminals.  See docs/rotators-serial.md.
"""
