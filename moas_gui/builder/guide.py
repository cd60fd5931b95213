"""The new-station guide: a station's stations and radios, its switches and their ports,
and its antennas with their bands, made into a file ``--check`` accepts.

The guide asks for what a builder knows without the manual: which radios there are and
which switch port (1-6, the amplifier-keying and inhibit connectors) each is wired to;
which switches and on which serial port; which antennas, on which output of the antenna
switch, for which bands.  It lays the relays out the way ``docs/configuration.md``
section 3 advises: the antenna switch first (on a 2xN switch, the first radio's N
relays, then the next radio's), then, when the station has them, one block per radio
for a switched band filter.  Everything it makes goes into a :class:`Document` as
ordinary edits, in one undo step, so the builder's pages show it at once and the user
goes on from there.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from moas_gui.config.model import RadioRef

from .document import Document

BAND_EDGES: tuple[tuple[str, float, float], ...] = (
    ("160 m", 1800, 2000), ("80 m", 3500, 4000), ("60 m", 5330, 5410), ("40 m", 7000, 7300),
    ("30 m", 10100, 10150), ("20 m", 14000, 14350), ("17 m", 18068, 18168),
    ("15 m", 21000, 21450), ("12 m", 24890, 24990), ("10 m", 28000, 29700),
    ("6 m", 50000, 54000), ("2 m", 144000, 148000),
)
"""The bands the guide offers (name, lower and upper edge in kHz)."""


def band(name: str) -> tuple[float, float]:
    """The edges of a band by its name ("20 m")."""
    for known, lower, upper in BAND_EDGES:
        if known == name:
            return lower, upper
    raise ValueError(f"{name!r} is not a band the guide knows")


@dataclass(frozen=True, slots=True)
class GuideSwitch:
    id: int = 1
    port: str = "emulator"
    """The serial port ("COM8", "/dev/ttyUSB0") or "emulator"."""


@dataclass(frozen=True, slots=True)
class GuideRadio:
    station: int
    radio: int
    port: int
    """The switch port (1-6) the radio's keying and inhibit lines are wired to."""
    switch: int = 1

    @property
    def ref(self) -> RadioRef:
        return RadioRef(self.station, self.radio)


@dataclass(frozen=True, slots=True)
class GuideAntenna:
    id: int
    short_name: str
    output: int
    """The output of the antenna switch (1 to its size) the antenna is on."""
    bands: tuple[tuple[float, float], ...]
    long_name: str = ""
    template: str = ""
    own: bool = True
    """One radio at a time (the antenna conflicts with itself, ``Conflicts: [ID]``)."""
    fast: tuple[int, ...] = ()
    rx_only: bool = False
    tx_only: bool = False


@dataclass(slots=True)
class Guide:
    """A new station's answers (see the module docstring)."""

    radios: list[GuideRadio]
    antennas: list[GuideAntenna]
    switches: list[GuideSwitch] = field(default_factory=lambda: [GuideSwitch()])
    outputs: int = 6
    """The antenna switch's size: a 2x6 has 6 outputs per radio."""
    first_relay: int = 0
    """The antenna switch's first relay."""
    filters: dict[RadioRef, int] = field(default_factory=dict)
    """Each radio's first band-filter relay, when it has a switched filter."""
    filter_bands: tuple[tuple[float, float], ...] = ()
    """The filter's bands in the order of its relays (a band not listed: the filter's
    last relay, its "other" position)."""

    def problems(self) -> list[str]:
        """What is missing or contradictory, in words (nothing: the guide can be applied)."""
        out = []
        if not self.radios:
            out.append("a station needs at least one radio")
        if not self.switches:
            out.append("a station needs at least one switch")
        refs = [r.ref for r in self.radios]
        if len(set(refs)) != len(refs):
            out.append("each station and radio may be given once")
        switch_ids = {s.id for s in self.switches}
        out += [f"station {r.station} radio {r.radio} is on switch {r.switch}, which is not "
                "given" for r in self.radios if r.switch not in switch_ids]
        ports = [(r.switch, r.port) for r in self.radios]
        if len(set(ports)) != len(ports):
            out.append("two radios are on one switch port")
        ids = [a.id for a in self.antennas]
        if len(set(ids)) != len(ids):
            out.append("each antenna needs its own number")
        out += [f"antenna {a.id} is on output {a.output}, beyond the switch's "
                f"{self.outputs}" for a in self.antennas if not 1 <= a.output <= self.outputs]
        out += [f"antenna {a.id} has no band" for a in self.antennas if not a.bands]
        if (len(self.radios) * self.outputs + self.first_relay) > 64:
            out.append(f"{len(self.radios)} radios x {self.outputs} outputs need more than "
                       "the switch's 64 relays")
        return out

    def relays(self, radio_index: int, antenna: GuideAntenna,
               lower: float, upper: float) -> list[int]:
        """The relays that put ``antenna`` on radio number ``radio_index`` (0 first) for a band."""
        radio = self.radios[radio_index]
        out = [self.first_relay + radio_index * self.outputs + antenna.output - 1]
        first = self.filters.get(radio.ref)
        if first is not None:
            edges = list(self.filter_bands)
            position = edges.index((lower, upper)) if (lower, upper) in edges else len(edges)
            out.append(first + position)
        return out

    def antenna_value(self, antenna: GuideAntenna) -> dict[str, object]:
        value: dict[str, object] = {"ID": antenna.id}
        if antenna.template:
            value["Template"] = antenna.template
        value["ShortName"] = antenna.short_name
        value["LongName"] = antenna.long_name or antenna.short_name
        if antenna.rx_only:
            value["RXOnly"] = True
        if antenna.tx_only:
            value["TXOnly"] = True
        if antenna.own:
            value["Conflicts"] = [antenna.id]
        if antenna.fast:
            value["Fast"] = list(antenna.fast)
        value["Control"] = [
            {"LowerFrequency": lower, "UpperFrequency": upper,
             "Stations": [{"Station": r.station, "Radio": r.radio,
                           "Relays": self.relays(i, antenna, lower, upper)}
                          for i, r in enumerate(self.radios)]}
            for lower, upper in antenna.bands]
        return value

    def radio_value(self, radio: GuideRadio) -> dict[str, object]:
        port: dict[str, object] = {"Port": radio.port}
        if radio.switch != 1:
            port = {"Switch": radio.switch, "Port": radio.port}
        return {"Station": radio.station, "Radio": radio.radio, "Switches": [port]}


def apply_guide(doc: Document, guide: Guide) -> None:
    """Write the guide's station into ``doc`` (one undo step); :class:`ValueError` with
    every problem when the answers cannot make a station."""
    problems = guide.problems()
    if problems:
        raise ValueError("; ".join(problems))
    with doc.transaction("new station from the guide"):
        for antenna in guide.antennas:
            doc.append(("Antennas",), guide.antenna_value(antenna))
        for radio in guide.radios:
            doc.append(("Radios",), guide.radio_value(radio))
        for switch in guide.switches:
            doc.append(("Switches",), {"ID": switch.id, "Port": switch.port})


__all__ = ["BAND_EDGES", "Guide", "GuideAntenna", "GuideRadio", "GuideSwitch", "apply_guide", "band"]
