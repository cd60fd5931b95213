"""The client's copy of the server's views stays in step with the engine's.

``moas_gui/client/model.py`` copies the view classes the server sends
(``engine/views.py``, the rotators' ``RotatorView``, the engine's ``Why``) on
purpose: the client must not import the engine.  Nothing in the code ties the
two copies together, so this test does: every field of an engine view has a
field of the same name in its client counterpart, unless :data:`LEFT_OUT`
says why the client does without it.  A new engine view class needs a client
counterpart in :data:`COUNTERPARTS` too."""

from __future__ import annotations

import dataclasses
import inspect
from collections.abc import Mapping

import pytest

from moas_gui.client import model as client
from moas_gui.engine import views as engine_views
from moas_gui.engine.why import Why
from moas_gui.hw.rotators.base import RotatorView as EngineRotatorView

COUNTERPARTS: dict[type, type] = {
    engine_views.RadioView: client.RadioView,
    engine_views.AntennaView: client.AntennaView,
    engine_views.ButtonView: client.ButtonView,
    engine_views.LayoutView: client.LayoutView,
    EngineRotatorView: client.RotatorView,
    Why: client.WhyView,
}
"""Each view class the server sends, and the client's copy of it."""

LEFT_OUT: dict[tuple[type, str], str] = {}
"""``(engine view class, field)``: why the client has no field for it.  Empty today:
the client reads every field the engine's views carry."""


def missing_fields(engine: type, copy: type,
                   left_out: Mapping[tuple[type, str], str]) -> list[str]:
    """The fields of ``engine`` that ``copy`` lacks and ``left_out`` does not explain."""
    have = {f.name for f in dataclasses.fields(copy)}
    return [f"{engine.__module__}.{engine.__qualname__}.{f.name} has no counterpart in "
            f"{copy.__module__}.{copy.__qualname__}"
            for f in dataclasses.fields(engine)
            if f.name not in have and (engine, f.name) not in left_out]


@pytest.mark.parametrize("engine", list(COUNTERPARTS), ids=lambda c: c.__qualname__)
def test_every_field_of_an_engine_view_is_in_the_clients_copy(engine: type) -> None:
    assert missing_fields(engine, COUNTERPARTS[engine], LEFT_OUT) == []


def test_every_view_class_of_the_engine_has_a_client_counterpart() -> None:
    views = {cls for _, cls in inspect.getmembers(engine_views, inspect.isclass)
             if dataclasses.is_dataclass(cls) and cls.__module__ == engine_views.__name__}
    assert views, "engine/views.py defines no view classes"
    assert views - set(COUNTERPARTS) == set()


def test_every_reason_left_out_names_a_field_that_exists() -> None:
    """A stale entry (the field is gone from the engine, or the client has it now) is
    an error too, so the list says only what is true."""
    for (engine, name), why in LEFT_OUT.items():
        assert name in {f.name for f in dataclasses.fields(engine)}, (engine, name)
        assert name not in {f.name for f in dataclasses.fields(COUNTERPARTS[engine])}
        assert why.strip(), (engine, name)


# -- the check can fail ---------------------------------------------------------------------------


@dataclasses.dataclass(frozen=True)
class _GrownRadioView(engine_views.RadioView):
    """The engine's radio view as it would be after a new field was added."""

    band: str = ""


def test_a_new_engine_field_without_a_client_counterpart_is_reported() -> None:
    found = missing_fields(_GrownRadioView, client.RadioView, LEFT_OUT)
    assert len(found) == 1 and ".band has no counterpart in moas_gui.client.model.RadioView" \
        in found[0], found


def test_a_field_the_list_explains_is_not_reported() -> None:
    explained = {(_GrownRadioView, "band"): "the client shows no band (an example)"}
    assert missing_fields(_GrownRadioView, client.RadioView, explained) == []


def test_a_client_copy_that_lost_a_field_is_reported() -> None:
    fields = [(f.name, f.type, f) for f in dataclasses.fields(client.RotatorView)
              if f.name != "has_stop"]
    shrunk = dataclasses.make_dataclass("RotatorView", fields, frozen=True)
    found = missing_fields(EngineRotatorView, shrunk, LEFT_OUT)
    assert len(found) == 1 and ".has_stop has no counterpart" in found[0], found
