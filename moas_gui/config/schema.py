"""The names each group of a ``.moas`` file may hold (chapter 6), and how to build it."""

from __future__ import annotations

from typing import Any

from . import model as m
from . import rigs
from .reading import (
    Field,
    GroupSpec,
    boolean,
    group_of,
    ignored,
    integer,
    list_of,
    number,
    one_of,
    text,
)

ID = integer(0, what="an identifier from 0 to 2,147,483,647")
INT = integer()
NONNEG = integer(0)
FREQ = number(0)
IDS = list_of(ID)
RELAYS = list_of(NONNEG, frozenset)
STRINGS = list_of(text)


def _range(values: dict[str, Any]) -> m.FrequencyRange:
    lower = values.pop("lower", None)
    upper = values.pop("upper", None)
    if lower is not None and upper is not None and lower > upper:
        raise ValueError(f"LowerFrequency {lower:g} is above UpperFrequency {upper:g}")
    return m.FrequencyRange(lower, upper)


def _with_range(cls: Any) -> Any:
    def build(values: dict[str, Any]) -> Any:
        values["range"] = _range(values)
        return cls(**values)
    return build


def _spec(cls: Any, fields: dict[str, Field], ranged: bool = False) -> GroupSpec:
    return GroupSpec(fields, _with_range(cls) if ranged else (lambda values: cls(**values)))


RANGE_FIELDS = {
    "LowerFrequency": Field("lower", FREQ, meaning="lower frequency in kHz"),
    "UpperFrequency": Field("upper", FREQ, meaning="upper frequency in kHz"),
}

TEMPLATE_INFO = _spec(m.TemplateInfo, {
    **RANGE_FIELDS,
    "Elements": Field("elements", NONNEG),
    "3dBWidth": Field("beamwidth_3db", number(0, 360)),
    "Lobes": Field("lobes", NONNEG),
}, ranged=True)

TEMPLATE = _spec(m.Template, {
    "Name": Field("name", text, required=True, meaning="the template's name"),
    "Manufacturer": Field("manufacturer", text),
    "Model": Field("model", text),
    "Type": Field("type", text),
    "Info": Field("info", list_of(group_of(TEMPLATE_INFO, "Info entry"))),
})

STATION_RELAYS = _spec(m.StationRelays, {
    "Station": Field("station", ID),
    "Radio": Field("radio", ID),
    "RadioRXAntenna": Field("radio_rx_antenna", boolean),
    "Relays": Field("relays", RELAYS),
    "RXRelays": Field("rx_relays", RELAYS),
    "PersistentRelays": Field("persistent_relays", RELAYS),
})

CONTROL = _spec(m.ControlRange, {
    **RANGE_FIELDS,
    "Stations": Field("stations", list_of(group_of(STATION_RELAYS, "Stations entry"))),
}, ranged=True)

ANTENNA = _spec(m.Antenna, {
    "ID": Field("id", ID, required=True, meaning="a unique number for this antenna"),
    "DisplayName": Field("display_name", text),
    "Template": Field("template", text),
    "ShortName": Field("short_name", text),
    "LongName": Field("long_name", text),
    "Enabled": Field("enabled", boolean),
    "RXOnly": Field("rx_only", boolean),
    "TXOnly": Field("tx_only", boolean),
    "NoSelect": Field("no_select", boolean),
    "Inhibit": Field("inhibit", boolean),
    "SharedTX": Field("shared_tx", boolean),
    "InUse": Field("in_use", IDS),
    "Rotator": Field("rotator", ID),
    "Offset": Field("offset", integer(-360, 720)),
    "Alternate": Field("alternate", IDS),
    "Conflicts": Field("conflicts", IDS),
    "Fast": Field("fast", IDS),
    "Control": Field("control", list_of(group_of(CONTROL, "Control entry"))),
})

SYSTEM = _spec(m.System, {
    "ID": Field("id", ID, required=True, meaning="a unique number for this system"),
    "DisplayName": Field("display_name", text),
    "Antennas": Field("antenna_count", NONNEG),
    "AdditiveAntennas": Field("additive_antennas", IDS),
    "ExclusiveAntennas": Field("exclusive_antennas", IDS),
    "SharedAntennas": Field("shared_antennas", IDS),
    "AdditiveSystems": Field("additive_systems", IDS),
    "ExclusiveSystems": Field("exclusive_systems", IDS),
    "SharedSystems": Field("shared_systems", IDS),
    "Shared": Field("shared", boolean),
})

FUNCTION = _spec(m.Function, {
    "ID": Field("id", ID, required=True, meaning="a unique number for this function"),
    "DisplayName": Field("display_name", text),
    "Name": Field("name", one_of(*m.FUNCTION_NAMES), required=True,
                  meaning="the function the server runs, such as \"AntennaSwap\""),
    "ShortName": Field("short_name", text),
    "LongName": Field("long_name", text),
    "Longname": Field("long_name", text),
    "IntParams": Field("int_params", list_of(INT)),
    "StringParams": Field("string_params", STRINGS),
})


def _button(values: dict[str, Any]) -> m.Button:
    values["type"] = m.ButtonType(values["type"])
    return m.Button(**values)


BUTTON = GroupSpec({
    "Row": Field("row", NONNEG, required=True, meaning="the button's row, 0 at the top"),
    "Column": Field("column", NONNEG, required=True, meaning="the button's column, 0 at the left"),
    "Type": Field("type", one_of("Antenna", "Function"), required=True,
                  meaning='"Antenna" or "Function"'),
    "ID": Field("id", ID, required=True, meaning="the antenna or function shown"),
}, _button)

MATRIX = _spec(m.MatrixEntry, {
    **RANGE_FIELDS,
    "Buttons": Field("buttons", list_of(group_of(BUTTON, "Buttons entry"))),
}, ranged=True)

LAYOUT = _spec(m.Layout, {
    "Rows": Field("rows", integer(1, 1000)),
    "Columns": Field("columns", integer(1, 1000)),
    "Station": Field("station", ID),
    "Radio": Field("radio", ID),
    "Matrix": Field("matrix", list_of(group_of(MATRIX, "Matrix entry"))),
})

RELATIVE_RANGE = _spec(m.RelativeRange, {
    **RANGE_FIELDS,
    "IDs": Field("ids", IDS, required=True, meaning="the antennas in relative order"),
    "RXIDs": Field("rx_ids", IDS),
}, ranged=True)

RELATIVE = _spec(m.RelativeAntennas, {
    "Station": Field("station", ID),
    "Radio": Field("radio", ID),
    "Antennas": Field("antennas", list_of(group_of(RELATIVE_RANGE, "Antennas entry")),
                      required=True, meaning="the relative antenna lists"),
})


def _rotator(values: dict[str, Any]) -> m.Rotator:
    if "control" in values:
        values["control"] = m.RotatorControl(values["control"])
    return m.Rotator(**values)


ROTATOR = GroupSpec({
    "ID": Field("id", ID, required=True, meaning="a unique number for this rotator"),
    "ShortName": Field("short_name", text),
    "LongName": Field("long_name", text),
    "DisplayName": Field(None, ignored),
    "Invisible": Field("invisible", boolean),
    "CCWLimit": Field("ccw_limit", integer(-360, 720)),
    "Rotation": Field("rotation", integer(1, 720)),
    "HasStop": Field("has_stop", boolean),
    "Control": Field("control", one_of(*(c.value for c in m.RotatorControl))),
    "Address": Field("address", text),
    "CommPort": Field("comm_port", text),
    "Model": Field("model", text),
    "Poll": Field("poll", integer(50, 600_000)),
    "Port": Field("port", integer(1, 2)),
    "RotctldPort": Field("rotctld_port", integer(1, 65535)),
    "ParkHeading": Field("park_heading", integer(0, 359)),
}, _rotator)

RADIO_REF = _spec(m.RadioRef, {
    "Station": Field("station", ID, required=True, meaning="the station number"),
    "Radio": Field("radio", ID, required=True, meaning="the radio number"),
})


def _switch_port(values: dict[str, Any]) -> m.SwitchPort:
    return m.SwitchPort(values.get("switch", 0), values["port"])


SWITCH_PORT = GroupSpec({
    "Switch": Field("switch", integer(1, 99)),
    "Port": Field("port", integer(1, 6), required=True, meaning="the switch port 1-6"),
}, _switch_port)

ALTERNATE_RULE = _spec(m.AlternateRule, {
    **RANGE_FIELDS,
    "ThisAntennas": Field("this_antennas", IDS),
    "OtherAntennas": Field("other_antennas", IDS),
    "Antenna": Field("antenna", ID),
}, ranged=True)

TRANSMIT_RELAYS = _spec(m.TransmitRelays, {
    **RANGE_FIELDS,
    "Extra": Field("extra", RELAYS),
    "Set": Field("set", RELAYS),
    "Reset": Field("reset", RELAYS),
}, ranged=True)

REFS = list_of(group_of(RADIO_REF, "station and radio"))

RADIO = _spec(m.Radio, {
    "Station": Field("station", ID, required=True, meaning="the station number"),
    "Radio": Field("radio", ID, required=True, meaning="the radio number"),
    "DisplayName": Field(None, ignored),
    "SubReceiver": Field("sub_receiver", ID),
    "PersistSubReceiver": Field("persist_sub_receiver", boolean),
    "UseMainFreq": Field("use_main_freq", boolean),
    "AltReceiver": Field("alt_receiver", ID),
    "Interrupt": Field("interrupt", boolean),
    "InterruptModeDelay": Field("interrupt_mode_delay", integer(0, 99)),
    "Always": Field("always", REFS),
    "SameBand": Field("same_band", REFS),
    "Partner": Field("partner", REFS),
    "InhibitBuss": Field("inhibit_buss", list_of(INT)),
    "Alternate": Field("alternate", list_of(group_of(ALTERNATE_RULE, "Alternate entry"))),
    "AltActive": Field("alt_active", REFS),
    "OutOfBand": Field("out_of_band", boolean),
    "InhibitOnlyOnTransmit": Field("inhibit_only_on_transmit", boolean),
    "Switches": Field("switches", list_of(group_of(SWITCH_PORT, "Switches entry")),
                      required=True, meaning="the switch ports this radio is wired to"),
    "Relays": Field("relays", list_of(group_of(TRANSMIT_RELAYS, "Relays entry"))),
})

SWITCH = _spec(m.Switch, {
    "ID": Field("id", integer(1, 99, "a switch number from 1 to 99"), required=True,
                meaning="the switch number 1-99"),
    "DisplayName": Field(None, ignored),
    "Type": Field("type", one_of("MOAS II")),
    "Method": Field("method", one_of("Serial")),
    "Port": Field("port", text, required=True,
                  meaning='the serial port, such as "COM8" or "/dev/ttyUSB0", or "emulator"'),
    "Echo": Field("echo", integer(0, 99)),
    "InhibitTime": Field("inhibit_time", integer(1, 9999)),
    "InterruptModeDelay": Field("interrupt_mode_delay", integer(0, 99)),
    "IndicateTR": Field("indicate_tr", boolean),
})

N1MM = _spec(m.N1MMStation, {
    "Address": Field("address", text, meaning="the logging computer's IP address"),
    "StationName": Field("station_name", text,
                         meaning="the logging computer's name, as N1MM sends it in StationName"),
    "Station": Field("station", ID, required=True, meaning="the station number for it"),
})

WINTEST = _spec(m.WinTestStation, {
    "StationName": Field("station_name", text, required=True,
                         meaning="the station name Win-Test broadcasts for that computer"),
    "Station": Field("station", ID, required=True, meaning="the station number for it"),
    "Radio": Field("radio", ID, meaning="the radio number for it (default 1)"),
})

RETRY = number(rigs.LOWEST_RETRY, rigs.HIGHEST_RETRY)


def _rig_daemon(default_port: int) -> GroupSpec:
    return _spec(rigs.RigDaemon, {
        "Station": Field("station", ID, required=True, meaning="the station number"),
        "Radio": Field("radio", ID, meaning="the radio number (default 1)"),
        "Address": Field("address", text, meaning=f"[host:]port (default 127.0.0.1:{default_port})"),
        "Rate": Field("rate", number(rigs.LOWEST_RATE, rigs.HIGHEST_RATE),
                      meaning="polls a second (default 10)"),
        "Retry": Field("retry", RETRY, meaning="seconds before the first new attempt"),
        "Enabled": Field("enabled", boolean),
    })


AUX_ANTENNA = _spec(rigs.AuxAntennaEntry, {
    "Value": Field("value", integer(0, 255), required=True,
                   meaning="the AUX value 0-255 the logger sends"),
    "Antenna": Field("antenna", ID, required=True, meaning="the antenna it selects"),
})

OTRSP = _spec(rigs.OtrspPort, {
    "Station": Field("station", ID, required=True, meaning="the station number"),
    "Port": Field("port", text, required=True,
                  meaning='the serial port the logger writes OTRSP to, such as "COM7"'),
    "Radio1": Field("radio1", ID),
    "Radio2": Field("radio2", ID),
    "AUX1": Field("aux1", list_of(group_of(AUX_ANTENNA, "AUX1 entry"))),
    "AUX2": Field("aux2", list_of(group_of(AUX_ANTENNA, "AUX2 entry"))),
    "Retry": Field("retry", RETRY, meaning="seconds before the first new attempt"),
    "Enabled": Field("enabled", boolean),
})

FLEX_RADIO = _spec(rigs.FlexRadioEntry, {
    "Address": Field("address", text, required=True,
                     meaning="the radio's address, serial number or nickname"),
    "Station": Field("station", ID, meaning="the station of radios 1 and 2 (default 1)"),
    "Slices": Field("slices", text, meaning='which slice feeds which radio, "A=1/1,B=1/2"'),
    "Retry": Field("retry", RETRY, meaning="seconds before the first new attempt"),
    "Enabled": Field("enabled", boolean),
})

TOP = GroupSpec({
    "Templates": Field("templates", list_of(group_of(TEMPLATE, "template"))),
    "Antennas": Field("antennas", list_of(group_of(ANTENNA, "antenna"))),
    "Systems": Field("systems", list_of(group_of(SYSTEM, "system"))),
    "Functions": Field("functions", list_of(group_of(FUNCTION, "function"))),
    "Layout": Field("layouts", list_of(group_of(LAYOUT, "layout"))),
    "RelativeAntennas": Field("relative_antennas", list_of(group_of(RELATIVE, "RelativeAntennas entry"))),
    "Rotators": Field("rotators", list_of(group_of(ROTATOR, "rotator"))),
    "Radios": Field("radios", list_of(group_of(RADIO, "radio"))),
    "Switches": Field("switches", list_of(group_of(SWITCH, "switch"))),
    "TCPPort": Field("tcp_port", integer(1, 65535)),
    "UDPPort": Field("udp_port", integer(1, 65535)),
    "WebPort": Field("web_port", integer(1, 65535)),
    "AGPort": Field("ag_port", integer(1, 65535)),
    "UseN1MMLogger": Field("use_n1mm_logger", boolean),
    "N1MMLogger": Field("n1mm_logger", list_of(group_of(N1MM, "N1MMLogger entry"))),
    "UseDXLog": Field("use_dxlog", boolean),
    "DXLogPort": Field("dxlog_port", integer(1, 65535)),
    "UseWinTest": Field("use_wintest", boolean),
    "WinTestPort": Field("wintest_port", integer(1, 65535)),
    "WinTest": Field("wintest", list_of(group_of(WINTEST, "WinTest entry"))),
    "UseN1MMRotor": Field("use_n1mm_rotor", boolean),
    "N1MMRotorPort": Field("n1mm_rotor_port", integer(1, 65535)),
    "N1MMRotorHeadings": Field("n1mm_rotor_headings", STRINGS),
    "Rigctld": Field("rigctld", list_of(group_of(_rig_daemon(rigs.RIGCTLD_PORT),
                                                 "Rigctld entry"))),
    "Flrig": Field("flrig", list_of(group_of(_rig_daemon(rigs.FLRIG_PORT), "Flrig entry"))),
    "OTRSP": Field("otrsp", list_of(group_of(OTRSP, "OTRSP entry"))),
    "FlexRadios": Field("flex_radios", list_of(group_of(FLEX_RADIO, "FlexRadios entry"))),
    "ProtectSameBand": Field("protect_same_band", boolean),
    "StartMOASRotator": Field("start_moas_rotator", boolean),
    "ClientAllow": Field("client_allow", STRINGS),
}, lambda values: values)

__all__ = ["TOP"]
