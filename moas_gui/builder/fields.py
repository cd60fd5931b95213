"""Every list and field of a ``.moas`` file as the builder's pages show them: what kind of
value each takes (so a page offers the values that make sense: antenna and radio
pickers, not numbers typed blind) and what it means in the manual's words (chapter 6's
tables, quoted with their section), for a tooltip or a side note.

Kinds: ``int``, ``number`` (kHz and other numbers), ``text``, ``bool``, ``choice`` (one of
``choices``), ``antenna`` / ``antennas`` (one or several antenna IDs), ``rotator``,
``template``, ``function``, ``systems``, ``station``, ``radio`` (a radio number of the
station), ``relays`` and ``ints`` (numbers), ``texts``, ``refs`` (stations and radios:
``[{"Station": 1, "Radio": 2}]``), ``target`` (a button's antenna or function) and
``groups`` (a list of groups, with its own ``fields``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from moas_gui.config.model import FUNCTION_NAMES
from moas_gui.config.validate import SERIAL_MODELS


@dataclass(frozen=True, slots=True)
class FieldSpec:
    key: str
    kind: str
    meaning: str
    """The manual's words for it."""
    section: str
    """The manual's section that says so ("6.4")."""
    required: bool = False
    choices: tuple[str, ...] = ()
    fields: tuple[FieldSpec, ...] = ()
    """A ``groups`` field's own fields."""
    columns: tuple[str, ...] = ()
    """A ``groups`` field's names shown in its table."""
    new: tuple[tuple[str, object], ...] = ()
    """A ``groups`` field's new item (an empty group can mean "every radio")."""

    def tooltip(self) -> str:
        need = "required" if self.required else "optional"
        return f"{self.key} ({need}): {self.meaning}. (MOAS II manual, section {self.section})"


@dataclass(frozen=True, slots=True)
class ListSpec:
    key: str
    """The file's name for the list ("Antennas"); empty for the miscellaneous items."""
    title: str
    section: str
    about: str
    """The manual's opening words for the list."""
    fields: tuple[FieldSpec, ...]
    columns: tuple[str, ...]
    new: dict[str, object] = field(default_factory=dict)
    """A new item's values (an ID is added, one above the highest)."""

    def field(self, key: str) -> FieldSpec | None:
        return next((f for f in self.fields if f.key == key), None)


def F(key: str, kind: str, meaning: str, section: str, required: bool = False,
      choices: tuple[str, ...] = (), fields: tuple[FieldSpec, ...] = (),
      columns: tuple[str, ...] = (), new: dict[str, object] | None = None) -> FieldSpec:
    return FieldSpec(key, kind, meaning, section, required, choices, fields, columns,
                     tuple((new or {}).items()))


def _range(section: str, what: str = "") -> tuple[FieldSpec, FieldSpec]:
    return (F("LowerFrequency", "number", f"Lower frequency{what} (kHz)", section),
            F("UpperFrequency", "number", f"Upper frequency{what} (kHz)", section))


INFO = (*_range("6.3.1", " limit"),
        F("Elements", "int", "Number of elements", "6.3.1"),
        F("3dBWidth", "number", "3 dB beamwidth", "6.3.1"),
        F("Lobes", "int", "Number of main lobes", "6.3.1"))

STATIONS = (
    F("Station", "station", "Station number", "6.4.2"),
    F("Radio", "radio", "Radio number", "6.4.2"),
    F("Relays", "relays", "Relays to select", "6.4.2"),
    F("RXRelays", "relays", "Relays to select when receiving on this antenna (if different "
                            "than TX)", "6.4.2"),
    F("PersistentRelays", "relays", "Relays to select when the other (TX or RX) antenna is "
                                    "part of a different group", "6.4.2"),
    F("RadioRXAntenna", "bool", "True if antenna is connected to radio RX antenna", "6.4.2"),
)

CONTROL = (*_range("6.4.1", " for these relays"),
           F("Stations", "groups", "Per-station and radio information", "6.4.1",
             fields=STATIONS, columns=("Station", "Radio", "Relays"),
             new={"Station": 1, "Radio": 1, "Relays": []}))

TEMPLATES = ListSpec("Templates", "Templates", "6.3",
                     "A template describes an antenna: its maker, model, type and, band by "
                     "band, its elements, beamwidth and lobes.", (
    F("Name", "text", "Template name", "6.3", required=True),
    F("Manufacturer", "text", "Antenna Manufacturer", "6.3"),
    F("Model", "text", "Antenna Model", "6.3"),
    F("Type", "text", "Antenna type: dipole, vertical, yagi, etc.", "6.3"),
    F("Info", "groups", "Frequency-specific information", "6.3", fields=INFO,
      columns=("LowerFrequency", "UpperFrequency", "Elements")),
), ("Name", "Type"), {"Name": "New template", "Info": []})

ANTENNAS = ListSpec("Antennas", "Antennas", "6.4",
                    "The antennas list describes antennas which can be selected. Each "
                    "antenna must have a unique ID number because other antennas and groups "
                    "refer to antenna using the ID number.", (
    F("ID", "int", "Unique number for this antenna", "6.4", required=True),
    F("ShortName", "text", "Name of antenna (put on buttons)", "6.4"),
    F("LongName", "text", "Descriptive name of antenna (used for display clients)", "6.4"),
    F("Template", "template", "Antenna template", "6.4"),
    F("Enabled", "bool", "True if antenna can be selected", "6.4"),
    F("RXOnly", "bool", "True if antenna is receive-only", "6.4"),
    F("TXOnly", "bool", "True if antenna is transmit-only", "6.4"),
    F("NoSelect", "bool", "True if antenna should not be considered as the best choice when "
                          "changing bands", "6.4"),
    F("Inhibit", "bool", "True if transmit should be inhibited when this antenna is selected "
                         "as the transmit antenna", "6.4"),
    F("SharedTX", "bool", "True if this antenna can be shared for transmit between "
                          "cooperating radios", "6.4"),
    F("InUse", "antennas", "If antenna is part of a system, the IDs of the antennas used", "6.4"),
    F("Rotator", "rotator", "Rotator number", "6.4"),
    F("Offset", "int", "Antenna offset from rotator position in degrees or the direction if "
                       "the antenna does not have a rotator", "6.4"),
    F("Alternate", "antennas", "Antenna numbers of antennas which are an alternate path for "
                               "connecting to this antenna", "6.4"),
    F("Conflicts", "antennas", "Antennas which cannot be used when this antenna is in use", "6.4"),
    F("Fast", "antennas", "Antennas to which a change from this one is fast (no slow "
                          "transition)", "5.6"),
    F("Control", "groups", "Relays used to control this antenna", "6.4", fields=CONTROL,
      columns=("LowerFrequency", "UpperFrequency"),
      new={"LowerFrequency": 14000, "UpperFrequency": 14350, "Stations": []}),
), ("ID", "ShortName", "LongName"), {"ShortName": "New", "Control": []})

SYSTEMS = ListSpec("Systems", "Systems", "6.5",
                   "A system is a group of antennas used together: additive antennas may be "
                   "selected together, exclusive ones one at a time.", (
    F("ID", "int", "Unique number for this system", "6.5", required=True),
    F("DisplayName", "text", "System name (ignored by the server)", "6.5"),
    F("Antennas", "int", "Number of antennas in the system", "6.5"),
    F("AdditiveAntennas", "antennas", "Antennas which are treated as additive", "6.5"),
    F("ExclusiveAntennas", "antennas", "Antennas which are treated as exclusive", "6.5"),
    F("SharedAntennas", "antennas", "Antennas for shared use", "6.5"),
    F("AdditiveSystems", "systems", "Systems which are treated as additive", "6.5"),
    F("ExclusiveSystems", "systems", "Systems which are treated as exclusive", "6.5"),
    F("SharedSystems", "systems", "Systems which are treated as shared (Not implemented yet)", "6.5"),
    F("Shared", "bool", "Initial state of antenna sharing", "6.5"),
), ("ID", "DisplayName"), {})

FUNCTIONS = ListSpec("Functions", "Functions", "6.6",
                     "Functions are actions a button runs: swap antennas, RX=TX, store and "
                     "recall, share, relays, inhibit, extra, partner, AltActive.", (
    F("ID", "int", "Unique number for this function", "6.6", required=True),
    F("Name", "choice", "Function name as known by the server", "6.6", required=True,
      choices=tuple(FUNCTION_NAMES)),
    F("ShortName", "text", "Name displayed for function", "6.6"),
    F("LongName", "text", "Fully descriptive name of function", "6.6"),
    F("IntParams", "ints", "Function-specific parameters", "6.6"),
    F("StringParams", "texts", "Function-specific parameters", "6.6"),
), ("ID", "Name", "ShortName"), {"Name": "AntennaSwap", "IntParams": [], "StringParams": []})

BUTTONS = (
    F("Row", "int", "Button row", "6.7.2", required=True),
    F("Column", "int", "Button column", "6.7.2", required=True),
    F("Type", "choice", "Must be Antenna or Function", "6.7.2", required=True,
      choices=("Antenna", "Function")),
    F("ID", "target", "Identifier of antenna or function", "6.7.2", required=True),
)

MATRIX = (*_range("6.7.1", " limit"),
          F("Buttons", "groups", "Button position and function", "6.7.1", fields=BUTTONS,
            columns=("Row", "Column", "Type", "ID"),
            new={"Row": 0, "Column": 0, "Type": "Antenna", "ID": 0}))

LAYOUTS = ListSpec("Layout", "Layouts", "6.7",
                   "A layout says which buttons a button client shows, band by band.", (
    F("Rows", "int", "Number of rows", "6.7"),
    F("Columns", "int", "Number of columns", "6.7"),
    F("Station", "station", "Station number", "6.7"),
    F("Radio", "radio", "Radio number", "6.7"),
    F("Matrix", "groups", "Button information", "6.7", fields=MATRIX,
      columns=("LowerFrequency", "UpperFrequency"), new={"Buttons": []}),
), ("Station", "Radio", "Rows", "Columns"), {"Rows": 2, "Columns": 4, "Matrix": []})

RELATIVE_RANGES = (*_range("6.8.1", " limit"),
                   F("IDs", "antennas", "IDs of antennas, in relative order", "6.8.1", required=True),
                   F("RXIDs", "antennas", "IDs of receive antennas", "6.8.1"))

RELATIVE = ListSpec("RelativeAntennas", "Relative antennas", "6.8",
                    "Relative antennas are the order a knob or a relative client steps "
                    "through, band by band.", (
    F("Station", "station", "Station number", "6.8"),
    F("Radio", "radio", "Radio number", "6.8"),
    F("Antennas", "groups", "Relative antennas", "6.8", required=True, fields=RELATIVE_RANGES,
      columns=("LowerFrequency", "UpperFrequency", "IDs"), new={"IDs": []}),
), ("Station", "Radio"), {"Antennas": []})

ROTATOR_CONTROLS = ("Test", "Electrical", "Serial", "RotatorGenius", "Hamlib")

ROTATORS = ListSpec("Rotators", "Rotators", "6.9",
                    "Rotators turn antennas; an antenna names its rotator.", (
    F("ID", "int", "Unique number for this rotator", "6.9", required=True),
    F("ShortName", "text", "Name of rotator", "6.9"),
    F("LongName", "text", "Descriptive name of rotator", "6.9"),
    F("Invisible", "bool", "True if rotator should not be shown to clients", "6.9"),
    F("CCWLimit", "int", "Counterclockwise limit in degrees", "6.9"),
    F("Rotation", "int", "Number of degrees the rotator can travel", "6.9"),
    F("HasStop", "bool", "True if the rotator has a stop", "6.9"),
    F("Control", "choice", "Type of rotator control", "6.9", choices=ROTATOR_CONTROLS),
    F("Address", "text", "Network address of the computer where the rotator is connected", "6.9"),
    F("CommPort", "text", "Name of communications port where the rotator is connected", "6.9"),
    F("Model", "choice", "Rotator model", "6.9", choices=tuple(SERIAL_MODELS)),
    F("Poll", "int", "How often to check direction in milliseconds", "6.9"),
), ("ID", "ShortName", "Control"), {"Control": "Test"})

REF = (F("Station", "station", "Station number", "6.10.3", required=True),
       F("Radio", "radio", "Radio number", "6.10.3", required=True))

ALTERNATE = (*_range("6.10.2"),
             F("ThisAntennas", "antennas", "Antennas this station might use for receive", "6.10.2"),
             F("OtherAntennas", "antennas", "Antennas other stations might use for transmit", "6.10.2"),
             F("Antenna", "antenna", "Alternate antenna to use", "6.10.2"))

TRANSMIT_RELAYS = (*_range("6.10.4"),
                   F("Extra", "relays", "Relays to be set during transmit", "6.10.4"),
                   F("Set", "relays", "Relays to be set when a station starts transmitting", "6.10.4"),
                   F("Reset", "relays", "Relays to be reset when a station starts transmitting", "6.10.4"))

SWITCH_PORTS = (F("Switch", "int", "Switch number", "6.10.1"),
                F("Port", "int", "Port number (1-6) on switch", "6.10.1", required=True))

RADIOS = ListSpec("Radios", "Radios", "6.10",
                  "Each radio: its station and radio numbers, the switch ports it is wired "
                  "to, its inhibits, partners, sub and alternate receivers.", (
    F("Station", "int", "Station number", "6.10", required=True),
    F("Radio", "int", "Radio number", "6.10", required=True),
    F("Switches", "groups", "Switches and switch ports", "6.10", required=True,
      fields=SWITCH_PORTS, columns=("Switch", "Port"), new={"Port": 1}),
    F("Interrupt", "bool", "True if interrupt mode, False if wait mode", "6.10"),
    F("InterruptModeDelay", "int", "Interrupt mode delay", "6.10"),
    F("SubReceiver", "radio", "Radio number of sub receiver", "6.10"),
    F("PersistSubReceiver", "bool", "True if the sub receiver relays should remain set during "
                                    "transmit", "6.10"),
    F("UseMainFreq", "bool", "True if the subreceiver antenna selection should be based on the "
                             "main radio frequency", "6.10"),
    F("AltReceiver", "radio", "Radio number of alternate receiver", "6.10"),
    F("Always", "refs", "Inhibit this station when one of these stations transmits", "6.10"),
    F("SameBand", "refs", "Inhibit this station when one of these stations transmit within the "
                          "frequency range of the receive antenna", "6.10"),
    F("Partner", "refs", "These stations are partners for shared transmit. Only one partner is "
                         "allowed.", "6.10"),
    F("InhibitBuss", "ints", "Inhibit buss numbers. All radios with the same bus number will "
                             "inhibit each other.", "6.10"),
    F("AltActive", "refs", "Stations which will cause this radio to use an alternate antenna "
                           "when they transmit.", "6.10"),
    F("OutOfBand", "bool", "True if inhibit this station if there is no transmit antenna "
                           "available which includes the transmit frequency", "6.10"),
    F("InhibitOnlyOnTransmit", "bool", "True if the inhibit output should be active only if the "
                                       "radio is transmitting", "6.10"),
    F("Alternate", "groups", "Alternate antennas to use for receive if another station is within "
                             "the frequency range of the receive antenna", "6.10",
      fields=ALTERNATE, columns=("LowerFrequency", "UpperFrequency", "Antenna")),
    F("Relays", "groups", "Frequencies and relays", "6.10", fields=TRANSMIT_RELAYS,
      columns=("LowerFrequency", "UpperFrequency", "Extra")),
), ("Station", "Radio"), {"Switches": []})

SWITCHES = ListSpec("Switches", "Switches", "6.11",
                    "Each MOAS II switch: its number and the serial port it is on.", (
    F("ID", "int", "Switch number", "6.11", required=True),
    F("Port", "text", "Communications port information (\"COM8\", \"/dev/ttyUSB0\" or "
                      "\"emulator\")", "6.11", required=True),
    F("Type", "choice", "Type of switch", "6.11", choices=("MOAS II",)),
    F("Method", "choice", "Communications method", "6.11", choices=("Serial",)),
    F("Echo", "int", "Number switch will send", "6.11"),
    F("InhibitTime", "int", "Slow transition milliseconds", "6.11"),
    F("InterruptModeDelay", "int", "Interrupt mode delay", "6.11"),
    F("IndicateTR", "bool", "Switch will send transmit and receive notifications to the MOAS "
                            "server.", "6.11"),
), ("ID", "Port"), {"Port": "emulator"})

N1MM = (F("Address", "text", "IP address of client", "6.12.1", required=True),
        F("Station", "station", "Station to use", "6.12.1", required=True))

MISCELLANEOUS = ListSpec("", "Miscellaneous", "6.12",
                         "The miscellaneous information is not a list. It is items within "
                         "the main group.", (
    F("TCPPort", "int", "TCP/IP port (clients; 12059 by default)", "6.12"),
    F("UDPPort", "int", "UDP port for N1MM Logger", "6.12"),
    F("UseN1MMLogger", "bool", "True if listening for N1MM Logger UDP messages", "6.12"),
    F("N1MMLogger", "groups", "N1MM Logger translations", "6.12", fields=N1MM,
      columns=("Address", "Station"), new={"Address": "127.0.0.1", "Station": 1}),
    F("ProtectSameBand", "bool", "True if second station on a band should have no antenna", "6.12"),
    F("StartMOASRotator", "bool", "True if the MOAS rotator program should be started if there "
                                  "are any rotators which need it.", "6.12"),
    F("WebPort", "int", "The browser client's port (this server's own item)", "6.12"),
    F("AGPort", "int", "The Antenna Genius port (this server's own item)", "6.12"),
    F("ClientAllow", "texts", "Networks whose clients may connect (this server's own item)", "6.12"),
), ())

LISTS: tuple[ListSpec, ...] = (TEMPLATES, ANTENNAS, SYSTEMS, FUNCTIONS, LAYOUTS, RELATIVE,
                               ROTATORS, RADIOS, SWITCHES, MISCELLANEOUS)
"""Every page of lists, in the file's order."""


def list_for(key: str) -> ListSpec:
    """The page of the file's top-level name ``key`` (a miscellaneous item's: that page)."""
    return next((spec for spec in LISTS if spec.key == key), MISCELLANEOUS)


__all__ = ["LISTS", "MISCELLANEOUS", "FieldSpec", "ListSpec", "list_for"]
