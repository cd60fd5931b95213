"""Findings of the station plan: what a configuration does that its author most likely did
not mean, each with the line of the file to look at (see :mod:`moas_gui.plan`)."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from moas_gui.config.model import AlternateRule, RadioRef
from moas_gui.engine import Engine, EngineError
from moas_gui.engine.index import ConfigIndex
from moas_gui.engine.rules import related
from moas_gui.engine.why import STEP_SAME_BAND_TAKEN

if TYPE_CHECKING:
    from . import Finding, Lines, Outcome, Plan


def find(plan: Plan, template: Engine, lines: Lines,
         in_time: Callable[[], None] = lambda: None) -> list[Finding]:
    """Every finding of ``plan`` (``template``: a new engine for the file, never changed;
    ``in_time`` may stop a search that takes too long)."""
    ix: ConfigIndex = template._ix
    out: list[Finding] = []
    out += _unreachable(plan, template, ix, lines, in_time)
    out += _without_antenna(plan, ix, lines)
    out += _blocked_pairs(plan, ix, lines)
    out += _every_same_band(plan, ix, lines)
    out += _alternates(plan, ix, lines)
    return out


def _finding(kind: str, line: int, text: str, radios: tuple[RadioRef, ...] = (),
             bands: tuple[str, ...] = ()) -> Finding:
    from . import Finding

    return Finding(kind, line, text, radios, bands)


def _radio(ref: RadioRef) -> str:
    return f"station {ref.station} radio {ref.radio}"


def _outcomes(plan: Plan) -> list[Outcome]:
    found = list(plan.alone)
    for _a, _b, _meet, scenarios in plan.pairs:
        for s in scenarios:
            found += [s.first, s.second]
    return found


def _unreachable(plan: Plan, template: Engine, ix: ConfigIndex, lines: Lines,
                 in_time: Callable[[], None]) -> list[Finding]:
    seen = {ix.canon[a] for o in _outcomes(plan) for a in (o.tx, o.rx) if a is not None}
    out = []
    for a in ix.ids:
        in_time()
        if ix.canon[a] != a or a in seen:
            continue
        ant = ix.antennas[a]
        users = [ref for ref in plan.radios if a in ix.radios[ref].paths]
        if not ant.enabled:
            why = "it is not enabled (Enabled is false)"
        elif not users:
            why = "no radio has relays for it"
        elif any(_pressable(template, ix, ref, a) for ref in users):
            continue
        else:
            why = ("no radio can select it, even by a press at a frequency it covers "
                   "(every try was refused)")
        out.append(_finding("unreachable_antenna", lines.antenna(a),
                            f"no radio can ever get {ix.name(a)} (antenna {a}): {why}"))
    return out


def _pressable(template: Engine, ix: ConfigIndex, ref: RadioRef, a: int) -> bool:
    """Whether ``ref`` gets ``a`` by a press at a frequency it covers (after a Share function,
    when the antenna belongs to a system that must be shared first)."""
    info = ix.radios[ref]
    segments = info.segments.get(a, ())
    if not segments:
        return False
    low, high = segments[0]
    khz = (low + high) / 2 if high - low < 1e9 else low + 1
    shares = [None] + sorted(f.id for f in ix.functions.values() if f.name == "Share")
    for share in shares:
        e = template.clone()
        try:
            e.set_frequency(ref.station, ref.radio, max(khz, 1.0))
            if share is not None:
                e.run_function(ref.station, ref.radio, share)
            e.select(ref.station, ref.radio, a, "both", exclusive=True)
        except EngineError:
            continue
        v = e.radio_view(ref.station, ref.radio)
        if any(x is not None and ix.canon[x] == ix.canon[a] for x in (v.tx, v.rx)):
            return True
    return False


def _without_antenna(plan: Plan, ix: ConfigIndex, lines: Lines) -> list[Finding]:
    out = []
    done: set[tuple[RadioRef, str]] = set()
    for band in plan.bands:
        for khz, _mode in band.frequencies:
            here = [o for o in plan.alone if o.khz == khz]
            for o in here:
                if o.has_antenna or (o.radio, band.name) in done:
                    continue
                found = _other_has_mine(ix, o, here)
                if found is None:
                    continue
                other, got = found
                done.add((o.radio, band.name))
                what = ("can transmit on no antenna" if o.receives else "gets no antenna")
                out.append(_finding(
                    "radio_without_antenna", lines.radio(o.radio),
                    f"{_radio(o.radio).capitalize()} {what} on {band.name} at {khz:g} kHz "
                    f"({o.text}), though {ix.name(got)} covers {khz:g} kHz for "
                    f"{_radio(other.radio)} and this radio has relays for it on other bands",
                    (o.radio,), (band.name,)))
    return out


def _other_has_mine(ix: ConfigIndex, o: Outcome,
                    here: list[Outcome]) -> tuple[Outcome, int] | None:
    """Another radio at ``o``'s frequency that got an antenna ``o``'s radio has relays for."""
    mine = {ix.canon[x] for x in ix.radios[o.radio].antennas}
    for other in here:
        got = other.tx if other.tx is not None else other.rx
        if other is not o and other.has_antenna and got is not None \
                and ix.canon[got] in mine:
            return other, got
    return None


def _alone(plan: Plan, ref: RadioRef, khz: float) -> Outcome | None:
    return plan.alone_at(ref, khz)


def _blocked_pairs(plan: Plan, ix: ConfigIndex, lines: Lines) -> list[Finding]:
    """Pairs of bands (or one band) on which two radios cannot both have an antenna (or
    both transmit), one finding per pair of radios, cause and loss, listing the bands."""
    groups: dict[tuple[str, int, str, str, RadioRef, RadioRef], list[str]] = {}
    for a, b, _meet, scenarios in plan.pairs:
        for s in scenarios:
            for loser, winner in ((s.second, s.first), (s.first, s.second)):
                alone = _alone(plan, loser.radio, loser.khz)
                if loser.has_antenna or alone is None or not alone.has_antenna:
                    continue
                if loser.rule == STEP_SAME_BAND_TAKEN:
                    continue  # same-band protection: the inhibit finding
                held = winner.tx if winner.tx is not None else winner.rx
                line, cause = _cause(ix, lines, alone, held)
                kind = "band_taken" if s.same_band else "band_pair_blocked"
                where = (s.first.band if s.same_band
                         else f"{s.first.band} + {s.second.band}")
                loss = (f"{_radio(loser.radio)} keeps only a receive antenna"
                        if loser.receives else "")
                found = groups.setdefault((kind, line, cause, loss, a, b), [])
                if where not in found:
                    found.append(where)
    out = []
    for (kind, line, cause, loss, a, b), bands in groups.items():
        what = "both transmit" if loss else "both have an antenna for their frequencies"
        tail = f" ({loss})" if loss else ""
        if kind == "band_taken":
            text = (f"{_radio(a)} and {_radio(b)} cannot {what} when both are "
                    f"on {_list(bands)}{tail}: {cause}")
        else:
            text = (f"{_radio(a)} and {_radio(b)} cannot {what} on "
                    f"{_list(bands)} (bands of {_radio(a)} + {_radio(b)}"
                    f"{'; ' + loss if loss else ''}): {cause}")
        out.append(_finding(kind, line, text, (a, b), tuple(bands)))
    return out


def _list(items: list[str]) -> str:
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " or " + items[-1]


def _cause(ix: ConfigIndex, lines: Lines, alone: Outcome,
           held: int | None) -> tuple[int, str]:
    """The line and words for why the antenna ``alone`` had was not free."""
    wanted = alone.tx if alone.tx is not None else alone.rx
    assert wanted is not None
    if held is None:
        return lines.antenna(wanted), f"{ix.name(wanted)} was not free"
    if ix.canon[held] == ix.canon[wanted]:
        return lines.antenna(wanted), (f"both need {ix.name(wanted)} (give one of them "
                                       "another antenna on its band)")
    parent = ix.systems.parent(ix.canon[wanted])
    held_parent = ix.systems.parent(ix.canon[held])
    if parent is not None and held_parent is not None and parent.system == held_parent.system:
        return lines.system(parent.system), (
            f"{ix.name(held)} and {ix.name(wanted)} are in system {parent.system}")
    if ix.antennas[wanted].conflicts and held in ix.antennas[wanted].conflicts:
        return lines.antenna(wanted, "Conflicts"), (
            f"{ix.name(wanted)} lists {ix.name(held)} in its Conflicts")
    if ix.antennas[held].conflicts and wanted in ix.antennas[held].conflicts:
        return lines.antenna(held, "Conflicts"), (
            f"{ix.name(held)} lists {ix.name(wanted)} in its Conflicts")
    return lines.antenna(wanted), f"{ix.name(wanted)} conflicts with {ix.name(held)}"


def _every_same_band(plan: Plan, ix: ConfigIndex, lines: Lines) -> list[Finding]:
    out = []
    for a, b, _meet, scenarios in plan.pairs:
        same = [s for s in scenarios if s.same_band and all(
            (x := _alone(plan, o.radio, o.khz)) is not None and x.has_antenna
            for o in (s.first, s.second))]
        if not same:
            continue
        protected = all(STEP_SAME_BAND_TAKEN in (s.first.rule, s.second.rule) for s in same)
        inhibited = all(s.first.inhibited_by or s.second.inhibited_by
                        or STEP_SAME_BAND_TAKEN in (s.first.rule, s.second.rule) for s in same)
        if protected:
            line = lines.key("ProtectSameBand")
            text = (f"{_radio(b)} gets no antenna whenever it joins {_radio(a)}'s band "
                    "(ProtectSameBand): the two can never share a band")
        elif inhibited:
            line = _inhibit_line(ix, lines, a, b)
            text = (f"on every band they share, one of {_radio(a)} and {_radio(b)} is "
                    "inhibited while the other transmits")
        else:
            continue
        out.append(_finding("inhibit_every_same_band", line, text, (a, b),
                            tuple(dict.fromkeys(s.first.band for s in same))))
    return out


def _inhibit_line(ix: ConfigIndex, lines: Lines, a: RadioRef, b: RadioRef) -> int:
    """The line that makes two radios inhibit each other: ``b``'s entry first, then
    ``a``'s; in each, its Always or SameBand naming the other, else its InhibitBuss
    (0 when none is found)."""
    ra, rb = ix.radios[a].radio, ix.radios[b].radio
    line = 0
    for ref, cfg, other in ((b, rb, a), (a, ra, b)):
        for key, refs in (("Always", cfg.always), ("SameBand", cfg.same_band)):
            if other in refs and not line:
                line = lines.radio(ref, key)
        if cfg.inhibit_buss and not line:
            line = lines.radio(ref, "InhibitBuss")
    return line


def _alternates(plan: Plan, ix: ConfigIndex, lines: Lines) -> list[Finding]:
    out = []
    for a in ix.ids:
        for alt in ix.antennas[a].alternate:
            if alt == a or alt not in ix.antennas:
                continue
            if not any(alt in ix.radios[ref].paths for ref in plan.radios):
                out.append(_finding(
                    "alternate_never_usable", lines.antenna(a, "Alternate"),
                    f"the alternate path {ix.name(alt)} (antenna {alt}) of {ix.name(a)} is never "
                    "usable: no radio has relays for it"))
    for ref in plan.radios:
        for rule in ix.radios[ref].radio.alternate:
            why = _rule_never_usable(ix, ref, rule)
            if why:
                out.append(_finding("alternate_never_usable", lines.radio(ref, "Alternate"),
                                    f"an Alternate rule of {_radio(ref)} is never usable: {why}",
                                    (ref,)))
            else:
                out += _alternate_transmitted_on(plan, ix, lines, ref, rule)
    return out


def _alternate_transmitted_on(plan: Plan, ix: ConfigIndex, lines: Lines, ref: RadioRef,
                              rule: AlternateRule) -> list[Finding]:
    """An ``Alternate`` rule whose alternate another radio can be transmitting on (the
    antenna itself, or one conflicting with it, in the rule's range) while the rule is in
    force: the radio setting it off, when it can transmit there, or any radio besides a
    radio setting it off.  Then the rule gives no antenna (5.9), shared transmit antenna or
    not (5.12 lets radios take turns transmitting, never listen while another transmits)."""
    named = rule.antenna
    assert named is not None
    takers = _takers(ix, [o for o in plan.radios if not related(ix, ref, o)], named, rule)
    if not takers:
        return []
    who = _list([_radio(o) + (f" (on {ix.name(y)}, which conflicts with it)" if y != named
                              else "") for o, y in takers])
    return [_finding(
        "alternate_can_be_transmitted_on", lines.radio(ref, "Alternate"),
        f"{_radio(ref)}'s Alternate rule switches it to receive on {ix.name(named)} "
        f"(antenna {named}), but {who} can be transmitting on that antenna when the rule "
        f"acts: then {_radio(ref)} receives on no antenna instead",
        (ref, *(o for o, _y in takers)))]


def _takers(ix: ConfigIndex, candidates: list[RadioRef], named: int,
            rule: AlternateRule) -> list[tuple[RadioRef, int]]:
    """The radios (each with an antenna) that can be transmitting on ``named`` or on an
    antenna conflicting with it while ``rule`` acts."""
    others = {ix.canon.get(a, a) for a in rule.other_antennas}

    def awaited(y: int) -> bool:
        return not others or ix.canon[y] in others

    triggers = {o for o in candidates
                if any(_transmits(ix, o, y, rule) and awaited(y) for y in ix.radios[o].paths)}
    takers: list[tuple[RadioRef, int]] = []
    for other in candidates:
        for y in sorted(ix.radios[other].paths):
            if not ix.conflict(named, y) or not _transmits(ix, other, y, rule):
                continue
            if (other in triggers and awaited(y)) or triggers - {other}:
                takers.append((other, y))
                break
    return takers


def _transmits(ix: ConfigIndex, radio: RadioRef, antenna: int, rule: AlternateRule) -> bool:
    """Whether ``radio`` can transmit on ``antenna`` somewhere in ``rule``'s range."""
    if ix.antennas[antenna].rx_only:
        return False
    return any((rule.range.upper is None or seg[0] <= rule.range.upper)
               and (rule.range.lower is None or seg[1] >= rule.range.lower)
               for seg in ix.radios[radio].segments.get(antenna, ()))


def _rule_never_usable(ix: ConfigIndex, ref: RadioRef, rule: AlternateRule) -> str:
    """Why a radio's ``Alternate`` rule can never act (empty when it can): it names no
    antenna, a transmit-only one, one that covers nothing of the rule's range for this
    radio, or one that conflicts with every antenna the rule waits for."""
    info = ix.radios[ref]
    named = rule.antenna
    if named is None or named not in ix.antennas:
        return "it names no antenna of the configuration"
    if ix.antennas[named].tx_only:
        return f"{ix.name(named)} is transmit only"
    if not any((rule.range.upper is None or seg[0] <= rule.range.upper)
               and (rule.range.lower is None or seg[1] >= rule.range.lower)
               for seg in info.segments.get(named, ())):
        return (f"{ix.name(named)} covers no frequency of the rule's range for "
                f"{_radio(ref)}")
    if rule.other_antennas and all(
            o in ix.antennas and ix.conflict(named, o) for o in rule.other_antennas):
        return (f"{ix.name(named)} conflicts with every antenna the rule waits for another "
                "radio to transmit on")
    return ""


__all__ = ["find"]
