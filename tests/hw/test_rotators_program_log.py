"""Lines the started MOAS Rotator program logs are relayed at their own level, once stamped."""

from __future__ import annotations

import logging

from moas_gui.hw.rotators.moas_rotator_process import relayed_line


def test_a_program_log_line_keeps_its_level_and_loses_its_own_stamp() -> None:
    assert relayed_line("2026-11-22 01:05:59,286 WARNING moas_gui.rotator_program.driver: "
                        "rotator 1 (Yaesu on COM3): cannot open COM3") == \
        (logging.WARNING, "rotator 1 (Yaesu on COM3): cannot open COM3")
    assert relayed_line("2026-11-22 01:05:59,286 ERROR x: broken") == (logging.ERROR, "broken")


def test_other_output_is_relayed_as_it_is_at_info() -> None:
    assert relayed_line("listening on 127.0.0.1:13020") == \
        (logging.INFO, "listening on 127.0.0.1:13020")
    assert relayed_line("2026-11-22 01:05:59,286 NOTALEVEL x: y") == \
        (logging.INFO, "y")
