"""Checks that need the whole file: references, duplicates, relays, systems.

Each check reads the built objects and reports through :class:`Reading`, which
knows the line and column every object came from.
"""

from __future__ import annotations

import ipaddress
from collections import defaultdict
from collections.abc import Iterable

from . import model as m
from .allow import allow_problems
from .circles import chain, circles
from .counted import MAX_RELAYS_PER_COMMAND, listed, missing_problems, relay_problems
from .jsontree import JObject
from .reading import Reading

SERIAL_MODELS = {
    "DCU1": 1, "RotorEZ": 2, "Yaesu": 4, "GS-232A": 4, "GS-232B": 4, "Alfaspid": 5,
    "RC2800P-A": 8, "RC2800P-X": 9, "Prosistel D": 10,
}
"""Rotator model names accepted for Serial rotators, with the MOAS Rotator numbers."""


class _Checker:
    def __init__(self, config: m.Config, reading: Reading) -> None:
        self.c = config
        self.r = reading
        self.antennas = {a.id for a in config.antennas}
        self.systems = {s.id for s in config.systems}
        self.functions = {f.id for f in config.functions}
        self.rotators = {r.id for r in config.rotators}
        self.radios = {r.ref for r in config.radios}
        self.stations = {r.station for r in config.radios}
        self.switches = {s.id for s in config.switches}

    # -- helpers -------------------------------------------------------------
    def duplicates(self, items: Iterable[object], key: str, what: str, ident: str = "ID") -> None:
        first: dict[object, object] = {}
        for item in items:
            value = getattr(item, key)
            if value in first:
                line = getattr(self.r.at(first[value]), "line", "?")
                self.r.error(self.r.at(item, ident), f"{what} {value} is defined twice "
                             f"(also on line {line}); each needs its own number")
            else:
                first[value] = item

    def antenna_refs(self, owner: object, key: str, ids: Iterable[int], what: str) -> None:
        missing = [antenna_id for antenna_id in ids if antenna_id not in self.antennas]
        one = f"{what} names antenna {missing[0]}, which is not in \"Antennas\"" if missing else ""
        missing_problems(self.r, owner, key, missing, what,
                         'antennas that are not in "Antennas"', one)

    def radio_ref(self, owner: object, key: str, station: int | None, radio: int | None,
                  what: str, value: object = None) -> bool:
        if station is None:
            return True
        if radio is None:
            if station not in self.stations:
                self.r.error(self.r.at(owner, key, value), f"{what} names station {station}, "
                             "which has no radio in \"Radios\"")
                return False
            return True
        if m.RadioRef(station, radio) not in self.radios:
            self.r.error(self.r.at(owner, key, value), f"{what} names station {station} radio "
                         f"{radio}, which is not in \"Radios\"")
            return False
        return True

    def relays(self, owner: object, key: str, relays: Iterable[int], what: str) -> None:
        relay_problems(self.r, self.switches, owner, key, relays, what)

    # -- the checks ----------------------------------------------------------
    def run(self) -> None:
        c = self.c
        self.duplicates(c.antennas, "id", "antenna")
        self.duplicates(c.systems, "id", "system")
        self.duplicates(c.functions, "id", "function")
        self.duplicates(c.rotators, "id", "rotator")
        self.duplicates(c.switches, "id", "switch")
        self.duplicates(c.templates, "name", "template", "Name")
        self.duplicates(c.radios, "ref", "radio on", "Radio")
        self.check_antennas()
        self.check_systems()
        self.check_functions()
        self.check_layouts()
        self.check_relative()
        self.check_rotators()
        self.check_radios()
        self.check_misc()

    def check_antennas(self) -> None:
        templates = {t.name for t in self.c.templates}
        for a in self.c.antennas:
            label = f"antenna {a.id}"
            self.antenna_refs(a, "InUse", a.in_use, label)
            self.antenna_refs(a, "Alternate", a.alternate, label)
            self.antenna_refs(a, "Conflicts", a.conflicts, label)
            self.antenna_refs(a, "Fast", a.fast, label)
            if a.rotator is not None and a.rotator not in self.rotators:
                self.r.error(self.r.at(a, "Rotator"), f"{label} uses rotator {a.rotator}, "
                             "which is not in \"Rotators\"")
            if a.template and templates and a.template not in templates:
                self.r.warning(self.r.at(a, "Template"), f"{label} names template "
                               f"\"{a.template}\", which is not in \"Templates\"")
            if a.rx_only and a.tx_only:
                self.r.error(self.r.at(a, "TXOnly"), f"{label} cannot be both RXOnly and TXOnly")
            for control in a.control:
                for entry in control.stations:
                    self.radio_ref(entry, "Station" if entry.radio is None else "Radio",
                                   entry.station, entry.radio, f"{label}'s Control")
                    for key, relays in (("Relays", entry.relays),
                                        ("RXRelays", entry.rx_relays or ()),
                                        ("PersistentRelays", entry.persistent_relays)):
                        self.relays(entry, key, relays, f"{label}'s Control")

    def check_systems(self) -> None:
        antenna_home: dict[int, m.System] = {}
        system_home: dict[int, m.System] = {}
        for s in self.c.systems:
            label = f"system {s.id}"
            here: set[int] = set()
            for key, ids in (("AdditiveAntennas", s.additive_antennas),
                             ("ExclusiveAntennas", s.exclusive_antennas),
                             ("SharedAntennas", s.shared_antennas)):
                self.antenna_refs(s, key, ids, label)
                twice: list[int] = []
                elsewhere: list[tuple[int, m.System]] = []
                for antenna_id in ids:
                    other = antenna_home.get(antenna_id)
                    if antenna_id in here:
                        twice.append(antenna_id)
                    elif other is not None:
                        elsewhere.append((antenna_id, other))
                    here.add(antenna_id)
                    antenna_home.setdefault(antenna_id, s)
                self._twice(s, key, twice, label)
                self._elsewhere(s, key, elsewhere, label, "antenna")
            for key, ids in (("AdditiveSystems", s.additive_systems),
                             ("ExclusiveSystems", s.exclusive_systems),
                             ("SharedSystems", s.shared_systems)):
                missing = [system_id for system_id in ids if system_id not in self.systems]
                one = (f"{label} names system {missing[0]}, which is not in \"Systems\""
                       if missing else "")
                missing_problems(self.r, s, key, missing, label,
                                 'systems that are not in "Systems"', one)
                taken: list[tuple[int, m.System]] = []
                if s.id in ids:
                    self.r.error(self.r.at(s, key, s.id), f"{label} contains itself")
                for system_id in ids:
                    if system_id not in self.systems or system_id == s.id:
                        continue
                    other = system_home.get(system_id)
                    if other is not None and other is not s:
                        taken.append((system_id, other))
                    system_home[system_id] = s
                self._elsewhere(s, key, taken, label, "system")
        # Systems that contain themselves through others.
        children: dict[int, tuple[int, ...]] = {}
        first: dict[int, m.System] = {}
        for s in self.c.systems:
            children.setdefault(s.id, s.member_systems)
            first.setdefault(s.id, s)
        for circle in circles(list(first), children):
            self.r.error(self.r.at(first[circle[0]]), "systems contain each other in a circle: "
                         + chain(circle))

    def _twice(self, s: m.System, key: str, twice: list[int], label: str) -> None:
        if len(twice) == 1:
            self.r.error(self.r.at(s, key, twice[0]),
                         f"antenna {twice[0]} is listed twice in {label}")
        elif twice:
            self.r.error(self.r.at(s, key, twice[0]), f"{len(twice):,} antennas are listed "
                         f"twice in {label} ({listed(twice)})")

    def _elsewhere(self, s: m.System, key: str, found: list[tuple[int, m.System]], label: str,
                   kind: str) -> None:
        if len(found) == 1:
            (ident, other), = found
            self.r.error(self.r.at(s, key, ident), f"{kind} {ident} is in {label} and in system "
                         f"{other.id}; {'an' if kind == 'antenna' else 'a'} {kind} can be part "
                         "of only one system")
        elif found:
            self.r.error(self.r.at(s, key, found[0][0]), f"{len(found):,} {kind}s of {label} "
                         "are also in other systems ("
                         + listed([f"{ident} in system {other.id}" for ident, other in found])
                         + f"); {'an' if kind == 'antenna' else 'a'} {kind} can be part of "
                         "only one system")

    def check_functions(self) -> None:
        for f in self.c.functions:
            self._function(f)

    def _function(self, f: m.Function) -> None:
        name = f.name
        if name in ("AntennaSwap", "Partner"):
            if self._need(f, 4, "four numbers: station and radio, station and radio"):
                self._param_radio(f, 0)
                self._param_radio(f, 2)
        elif name == "Share":
            self._share_params(f)
        elif name == "Relay":
            self._relay_params(f)
        elif name == "Inhibit":
            if self._need(f, 3, "three numbers: station, radio and inhibit buss"):
                self._param_radio(f, 0)
        elif name == "Extra":
            self._extra_params(f)
        elif name == "AltActive":
            self._alt_active_params(f)

    @staticmethod
    def _function_label(f: m.Function) -> str:
        return f"function {f.id} ({f.name})"

    def _need(self, f: m.Function, count: int, text: str, exact: bool = True) -> bool:
        """Whether a function has the count of ``IntParams`` its kind needs (exactly, or at
        least); if not, says so."""
        p = f.int_params
        if (len(p) != count) if exact else (len(p) < count):
            self.r.error(self.r.at(f, "IntParams"), f"{self._function_label(f)} needs {text} "
                         f"in \"IntParams\" but has {len(p)} number{'s' if len(p) != 1 else ''}")
            return False
        return True

    def _param_radio(self, f: m.Function, i: int) -> None:
        """The station and radio at ``IntParams[i]`` and ``[i + 1]`` name a radio."""
        p = f.int_params
        self.radio_ref(f, "IntParams", p[i], p[i + 1], self._function_label(f), value=p[i])

    def _share_params(self, f: m.Function) -> None:
        """Share: a system of the file, then antennas of the file."""
        p = f.int_params
        label = self._function_label(f)
        if self._need(f, 1, "the system number first, then any preferred antennas", exact=False):
            if p[0] not in self.systems:
                self.r.error(self.r.at(f, "IntParams"),
                             f"{label} names system {p[0]}, which is not in \"Systems\"")
            self.antenna_refs(f, "IntParams", p[1:], label)

    def _relay_params(self, f: m.Function) -> None:
        """Relay: a relay, optionally a station with its radio and antennas; string
        parameters among T, R and S."""
        p = f.int_params
        label = self._function_label(f)
        if self._need(f, 1, "the relay number, then optionally station, radio and antennas",
                      exact=False):
            self.relays(f, "IntParams", p[:1], label)
            if len(p) == 2:
                self.r.error(self.r.at(f, "IntParams"), f"{label} gives a station without a radio")
            if len(p) >= 3:
                self._param_radio(f, 1)
                self.antenna_refs(f, "IntParams", p[3:], label)
            for s in f.string_params:
                if s not in ("T", "R", "S"):
                    self.r.error(self.r.at(f, "StringParams", s),
                                 f"{label}: \"{s}\" is not one of \"T\", \"R\", \"S\"")

    def _extra_params(self, f: m.Function) -> None:
        """Extra: a radio and a relay; with "Transfer" two radios and a relay."""
        p = f.int_params
        label = self._function_label(f)
        if "Transfer" in f.string_params:
            if self._need(f, 5, "five numbers with \"Transfer\": station, radio, other station, "
                                "other radio, relay"):
                self._param_radio(f, 0)
                self._param_radio(f, 2)
                self.relays(f, "IntParams", p[4:], label)
        elif self._need(f, 3, "three numbers: station, radio and relay"):
            self._param_radio(f, 0)
            self.relays(f, "IntParams", p[2:], label)

    def _alt_active_params(self, f: m.Function) -> None:
        """AltActive: station and radio pairs, the radio first, then the radios that move
        it to its alternate."""
        p = f.int_params
        if not self._need(f, 4, "at least four numbers: the radio, then radios that move it",
                          exact=False):
            return
        if len(p) % 2:
            self.r.error(self.r.at(f, "IntParams"), f"{self._function_label(f)} needs station "
                         "and radio pairs, but has an odd count of numbers")
        for i in range(0, len(p) - 1, 2):
            self._param_radio(f, i)

    def check_layouts(self) -> None:
        for layout in self.c.layouts:
            self.radio_ref(layout, "Station" if layout.radio is None else "Radio",
                           layout.station, layout.radio, "this layout")
            for entry in layout.matrix:
                taken: dict[tuple[int, int], m.Button] = {}
                for b in entry.buttons:
                    known = self.antennas if b.type is m.ButtonType.ANTENNA else self.functions
                    if b.id not in known:
                        kind = "antenna" if b.type is m.ButtonType.ANTENNA else "function"
                        self.r.error(self.r.at(b, "ID"), f"this button shows {kind} {b.id}, "
                                     f"which is not in \"{'Antennas' if kind == 'antenna' else 'Functions'}\"")
                    if (layout.rows and b.row >= layout.rows) or (
                            layout.columns and b.column >= layout.columns):
                        self.r.error(self.r.at(b), f"this button at row {b.row} column {b.column} "
                                     f"lies outside the layout's {layout.rows} rows and "
                                     f"{layout.columns} columns (rows and columns count from 0)")
                    if (b.row, b.column) in taken:
                        self.r.error(self.r.at(b), f"two buttons at row {b.row} column "
                                     f"{b.column} in the same Matrix entry")
                    taken[(b.row, b.column)] = b

    def check_relative(self) -> None:
        for rel in self.c.relative_antennas:
            self.radio_ref(rel, "Station" if rel.radio is None else "Radio",
                           rel.station, rel.radio, "these relative antennas")
            for entry in rel.antennas:
                self.antenna_refs(entry, "IDs", entry.ids, "this relative list")
                if entry.rx_ids is not None:
                    self.antenna_refs(entry, "RXIDs", entry.rx_ids, "this relative list")
                    if len(entry.rx_ids) != len(entry.ids):
                        self.r.error(self.r.at(entry, "RXIDs"), f"\"RXIDs\" has "
                                     f"{len(entry.rx_ids)} antennas but \"IDs\" has "
                                     f"{len(entry.ids)}; they must be the same length")

    def check_rotators(self) -> None:
        users: dict[int, list[m.Antenna]] = defaultdict(list)
        for a in self.c.antennas:
            if a.rotator is not None:
                users[a.rotator].append(a)
        home: dict[int, m.System] = {}
        for s in self.c.systems:
            for antenna_id in s.member_antennas:
                home[antenna_id] = s
        for rot in self.c.rotators:
            label = f"rotator {rot.id}"
            node = self.r.node_of(rot)
            if rot.control is m.RotatorControl.SERIAL:
                self._serial_rotator(rot, label, node)
            elif rot.control in (m.RotatorControl.ROTATOR_GENIUS, m.RotatorControl.HAMLIB):
                if node is not None and node.get("Address") is None:
                    self.r.error(node, f"{label} is {rot.control.value} and needs \"Address\", "
                                 "the controller's host (and :port)")
            elif rot.control is m.RotatorControl.ELECTRICAL:
                self._electrical_rotator(rot, label, users.get(rot.id, []), home)

    def _serial_rotator(self, rot: m.Rotator, label: str, node: JObject | None) -> None:
        """A Serial rotator names the serial port on the MOAS Rotator computer and a known
        model (or a model number)."""
        if not rot.comm_port:
            self.r.error(node, f"{label} is Serial and needs \"CommPort\", the serial "
                         "port on the computer running MOAS Rotator")
        if not rot.model:
            self.r.error(node, f"{label} is Serial and needs \"Model\", one of "
                         + ", ".join(f'"{k}"' for k in SERIAL_MODELS))
        elif rot.model not in SERIAL_MODELS and not rot.model.isdigit():
            self.r.error(self.r.at(rot, "Model"), f"{label} has model \"{rot.model}\"; "
                         "known models are " + ", ".join(f'"{k}"' for k in SERIAL_MODELS))

    def _electrical_rotator(self, rot: m.Rotator, label: str, antennas: list[m.Antenna],
                            home: dict[int, m.System]) -> None:
        """Each antenna on an electrical rotator is part of a system, and every antenna of
        that system says it is on the same rotator."""
        checked: set[int] = set()
        for a in antennas:
            system = home.get(a.id)
            if system is None:
                self.r.error(self.r.at(a, "Rotator"), f"antenna {a.id} uses electrical "
                             f"{label}, so it must be part of an antenna system")
                continue
            if id(system) in checked:
                continue
            checked.add(id(system))
            for other in system.member_antennas:
                other_antenna = self.c.antenna(other)
                if other_antenna is not None and other_antenna.rotator != rot.id:
                    self.r.error(self.r.at(other_antenna), f"antenna {other} is in "
                                 f"system {system.id} with antennas of electrical {label}, "
                                 f"so it must also say \"Rotator\": {rot.id}")

    def check_radios(self) -> None:
        used_ports: dict[tuple[int, int], m.Radio] = {}
        single = next(iter(self.switches)) if len(self.switches) == 1 else None
        subs_of = {m.RadioRef(r.station, r.sub_receiver): r for r in self.c.radios
                   if r.sub_receiver is not None and r.sub_receiver != r.radio}
        for radio in self.c.radios:
            label = f"station {radio.station} radio {radio.radio}"
            self._radio_ports(radio, label, single, used_ports)
            self._radio_relations(radio, label)
            self._sub_flags(radio, label, subs_of)
            for rule in radio.alternate:
                self.antenna_refs(rule, "ThisAntennas", rule.this_antennas, f"{label}'s Alternate")
                self.antenna_refs(rule, "OtherAntennas", rule.other_antennas, f"{label}'s Alternate")
                if rule.antenna is not None:
                    self.antenna_refs(rule, "Antenna", (rule.antenna,), f"{label}'s Alternate")
            for entry in radio.relays:
                for key, relays in (("Extra", entry.extra), ("Set", entry.set),
                                    ("Reset", entry.reset)):
                    self.relays(entry, key, relays, f"{label}'s Relays")

    def _radio_ports(self, radio: m.Radio, label: str, single: int | None,
                     used_ports: dict[tuple[int, int], m.Radio]) -> None:
        """Each port of a radio is on a switch of the file (which one may go unsaid only
        when there is one switch) and no other radio's."""
        for sp in radio.switches:
            switch_id = sp.switch or single
            if sp.switch == 0 and single is None:
                self.r.error(self.r.at(radio, "Switches"), f"{label} must say which "
                             "\"Switch\" its port is on, because there is "
                             f"{'no switch' if not self.switches else 'more than one switch'}")
                continue
            if switch_id not in self.switches:
                self.r.error(self.r.at(radio, "Switches"), f"{label} is wired to switch "
                             f"{switch_id}, which is not in \"Switches\"")
                continue
            assert switch_id is not None
            other = used_ports.get((switch_id, sp.port))
            if other is not None:
                self.r.error(self.r.at(radio, "Switches"), f"{label} and station "
                             f"{other.station} radio {other.radio} are both on port {sp.port} "
                             f"of switch {switch_id}")
            used_ports[(switch_id, sp.port)] = radio

    def _radio_relations(self, radio: m.Radio, label: str) -> None:
        """The radios a radio names (Always, SameBand, Partner, AltActive) exist and are not
        itself (but for Partner); one partner at most; its sub and alternate receivers
        have entries of their own."""
        for key, refs in (("Always", radio.always), ("SameBand", radio.same_band),
                          ("Partner", radio.partner), ("AltActive", radio.alt_active)):
            for ref in refs:
                self.radio_ref(ref, "Radio", ref.station, ref.radio, f"{label}'s \"{key}\"")
                if ref == radio.ref and key != "Partner":
                    self.r.error(self.r.at(ref), f"{label} lists itself in \"{key}\"")
        if len(radio.partner) > 1:
            self.r.error(self.r.at(radio, "Partner"), f"{label} has {len(radio.partner)} "
                         "partners; only one is allowed")
        for key, number in (("SubReceiver", radio.sub_receiver),
                            ("AltReceiver", radio.alt_receiver)):
            if number is not None and m.RadioRef(radio.station, number) not in self.radios:
                self.r.error(self.r.at(radio, key), f"{label}'s \"{key}\" is radio {number}, "
                             f"but station {radio.station} has no radio {number} in \"Radios\"")

    def _sub_flags(self, radio: m.Radio, label: str, subs_of: dict[m.RadioRef, m.Radio]
                   ) -> None:
        """6.10's radio table lists PersistSubReceiver and UseMainFreq with SubReceiver: they
        belong on the main radio's entry.  On the sub receiver's own entry they still work."""
        for key, on in (("PersistSubReceiver", radio.persist_sub_receiver),
                        ("UseMainFreq", radio.use_main_freq)):
            if not on or radio.sub_receiver is not None:
                continue
            main = subs_of.get(radio.ref)
            if main is not None:
                self.r.warning(self.r.at(radio, key), f"{label}'s \"{key}\" belongs on the entry "
                               f"of its main radio, station {main.station} radio {main.radio}, "
                               "next to its \"SubReceiver\" (the manual's radio table, 6.10); "
                               "it is honoured here too")
            else:
                self.r.warning(self.r.at(radio, key), f"{label}'s \"{key}\" has no effect: "
                               f"{label} has no \"SubReceiver\" and is no radio's sub receiver; "
                               "it belongs on the entry of a radio with a \"SubReceiver\" (6.10)")

    def check_misc(self) -> None:
        c = self.c
        if not c.switches:
            self.r.warning(self.r.at(c, "Switches"), "there are no \"Switches\": the server will not control any relays")
        if not c.radios:
            self.r.warning(self.r.at(c, "Radios"), "there are no \"Radios\": no antenna can be selected")
        self._n1mm_entries()
        for station in c.wintest:
            self.radio_ref(station, "Station", station.station, station.radio,
                           "this WinTest entry")
        if c.use_wintest and not c.wintest:
            self.r.warning(self.r.at(c, "UseWinTest"), "UseWinTest is true but \"WinTest\" "
                           "lists no station names; every broadcast will be ignored")
        if c.use_dxlog and not c.n1mm_logger:
            self.r.warning(self.r.at(c, "UseDXLog"), "UseDXLog is true but \"N1MMLogger\" "
                           "lists no computers; every packet will be ignored")
        self._rotor_headings()
        if c.use_n1mm_rotor and not c.rotators:
            self.r.warning(self.r.at(c, "UseN1MMRotor"), "UseN1MMRotor is true but there are "
                           "no \"Rotators\" to turn")
        if c.use_n1mm_logger and not c.n1mm_logger:
            self.r.warning(self.r.at(c, "UseN1MMLogger"), "UseN1MMLogger is true but \"N1MMLogger\" lists no computers; "
                           "every packet will be ignored")
        allow_problems(c, self.r)

    def _n1mm_entries(self) -> None:
        """Each N1MMLogger entry names a station of the file and an IP address or a station
        name."""
        for entry in self.c.n1mm_logger:
            self.radio_ref(entry, "Station", entry.station, None, "this N1MMLogger entry")
            if not entry.address and not entry.station_name:
                self.r.error(self.r.at(entry, "Address"), "this N1MMLogger entry needs an "
                             "\"Address\" or a \"StationName\" (or both)")
                continue
            if not entry.address:
                continue
            try:
                ipaddress.ip_address(entry.address)
            except ValueError:
                self.r.error(self.r.at(entry, "Address"), f"\"{entry.address}\" is not an IP "
                             "address such as 192.168.1.20")

    def _rotor_headings(self) -> None:
        """Each N1MMRotorHeadings entry is host:port (the port 13010 when left out)."""
        for text in self.c.n1mm_rotor_headings:
            host, colon, port = text.strip().rpartition(":")
            if not colon:
                host, port = text.strip(), "13010"
            if not host or not port.isdigit() or not 1 <= int(port) <= 65535:
                self.r.error(self.r.at(self.c, "N1MMRotorHeadings", text), f"\"{text}\" is not "
                             "host:port, such as 192.168.1.20:13010")


def check(config: m.Config, reading: Reading) -> None:
    """Report every cross-reference problem of ``config`` through ``reading``."""
    _Checker(config, reading).run()


__all__ = ["MAX_RELAYS_PER_COMMAND", "SERIAL_MODELS", "check"]
