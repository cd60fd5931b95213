"""Stand-ins for tests, demos and client authors: never imported by the product.

Each module is imported by name; this package's ``__init__`` imports none of
them, so taking one loads only what it needs:

``fake_station`` / ``fake_backend``
    :class:`~moas_gui.testing.fake_backend.FakeBackend`, an in-memory station
    (:class:`~moas_gui.testing.fake_station.FakeStation`) with simple real
    rules behind the client protocol's backend seam.
``fake_server``
    ``python -m moas_gui.testing.fake_server [--port 12059]``: the client
    protocol over the fake backend, no switch or configuration needed; the
    place to develop a client against.
``fake_moas_rotator``
    :class:`~moas_gui.testing.fake_moas_rotator.FakeMoasRotator`, a stand-in
    for the MOAS Rotator program on loopback
    (``python -m moas_gui.testing.fake_moas_rotator --port N``).
``genius_server``
    :class:`~moas_gui.testing.genius_server.GeniusServer`, a Rotator Genius on
    loopback, over the pure :class:`~moas_gui.testing.genius_server.GeniusModel`.
``flex_radio``
    :class:`~moas_gui.testing.flex_radio.FlexRadio`, a FlexRadio's TCP API and
    discovery datagrams on loopback, written from the public API text
    (``python -m moas_gui.testing.flex_radio [--port 4992]``).
``faulty_controller``
    :class:`~moas_gui.testing.faulty_controller.FaultyController`, any serial
    rotator controller emulator made to go silent or noisy.
``control_hook``
    remote hands for the journey tests: a person's clicks on a running
    ``moas-server`` window, over a Unix socket (loaded through
    ``MOAS_GUI_CONTROL_HOOK``, see :mod:`moas_gui.ui.control_hook`).

The product's own emulators (the MOAS II switch emulator, ``moas-emulator``,
and the serial rotator controller emulators) are features and stay where they
are.  ``tests/rules/test_rule_testing_package.py`` fails when a module outside
this package imports it.
"""
