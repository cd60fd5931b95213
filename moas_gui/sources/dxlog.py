"""The DXLog.net source: DXLog's "Radio information" broadcast, N1MM-style RadioInfo.

DXLog.net sends the same ``<RadioInfo>`` XML as N1MM Logger+ when
*Options | Broadcast | Radio information* is on, to the address and port set
in *Options | Configure network*; its developer's tool (ICOMautomagic) gives
127.0.0.1 and 12060 as the default, while another third-party description
says 13063, so the port is configurable (see docs/sources.md).  DXLog also
broadcasts the sub-receiver in SO2V.  Which of the optional fields DXLog fills
(``TXFreq``, ``ActiveRadioNr``, ``IsTransmitting``...) is not published: the
parser takes what is there and treats the rest as unknown, as for N1MM.
"""

from __future__ import annotations

from typing import Final

from moas_gui.sources.n1mm import N1MMListener

DEFAULT_PORT: Final = 12060


class DXLogListener(N1MMListener):
    """An N1MM RadioInfo listener that names itself DXLog.net in logs and configuration."""

    kind = "dxlog"
    label = "DXLog.net"
    title = "DXLog.net"


__all__ = ["DEFAULT_PORT", "DXLogListener"]
