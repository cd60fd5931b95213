"""The icons: every file present and readable, non-empty at every size, states distinct by shape."""

from __future__ import annotations

import itertools
import struct

import pytest
from PySide6.QtCore import QRectF, QSize, Qt
from PySide6.QtGui import QColor, QImage, QPainter
from PySide6.QtSvg import QSvgRenderer
from PySide6.QtWidgets import QApplication

from moas_gui.status import DESCRIPTIONS, ServerState, overall_state
from moas_gui.ui import icons
from moas_gui.ui.icons import (
    APP_ICON,
    FILE_ICON,
    ICON_DIR,
    PNG_SIZES,
    build_icon,
    icon_path,
    status_icon,
    status_icon_name,
)

NAMES = [status_icon_name(state) for state in ServerState] + [FILE_ICON]


def render(name: str, size: int) -> QImage:
    image = QImage(size, size, QImage.Format.Format_ARGB32)
    image.fill(Qt.GlobalColor.transparent)
    painter = QPainter(image)
    painter.setRenderHint(QPainter.RenderHint.Antialiasing)
    QSvgRenderer(str(icon_path(name))).render(painter, QRectF(0, 0, size, size))
    painter.end()
    return image


def pixels(image: QImage) -> list[QColor]:
    image = image.convertToFormat(QImage.Format.Format_ARGB32)
    return [image.pixelColor(x, y) for y in range(image.height()) for x in range(image.width())]


def raw(image: QImage) -> bytes:
    converted = image.convertToFormat(QImage.Format.Format_ARGB32_Premultiplied)
    return bytes(converted.constBits())  # copied while ``converted`` still holds the pixels


def max_difference(a: QImage, b: QImage) -> int:
    """The largest difference of any colour channel of any pixel (0-255)."""
    assert (a.width(), a.height()) == (b.width(), b.height())
    return max(abs(x - y) for x, y in zip(raw(a), raw(b), strict=True))


def opaque_share(image: QImage) -> float:
    alpha = raw(image)[3::4]
    return sum(1 for a in alpha if a > 128) / len(alpha)


def foreground(image: QImage) -> list[bool]:
    """Where the picture is not the tile: the Yagi and the badge, whatever the tile's colour."""
    size = image.width()
    tile = image.pixelColor(int(3.5 * size / 16), int(12.5 * size / 16))
    return [c.alpha() > 128 and abs(c.red() - tile.red()) + abs(c.green() - tile.green())
            + abs(c.blue() - tile.blue()) > 120 for c in pixels(image)]


def test_every_icon_has_its_svg_and_a_png_at_every_size(qapp: QApplication) -> None:
    for name in NAMES:
        assert QSvgRenderer(str(icon_path(name))).isValid(), name
        for size in PNG_SIZES:
            png = QImage(str(icon_path(name, size)))
            assert not png.isNull(), f"{name}-{size}.png"
            assert (png.width(), png.height()) == (size, size)


@pytest.mark.parametrize("name", NAMES)
def test_each_icon_renders_solid_at_every_size(qapp: QApplication, name: str) -> None:
    for size in PNG_SIZES:
        share = opaque_share(render(name, size))
        assert share > 0.6, f"{name} at {size} px is {share:.0%} opaque"


def test_the_png_fallbacks_match_their_svg_drawings(qapp: QApplication) -> None:
    """scripts/make_icons.py was run after the last change of an SVG."""
    for name, size in itertools.product(NAMES, PNG_SIZES):
        worst = max_difference(render(name, size), QImage(str(icon_path(name, size))))
        assert worst <= 4, f"{name}-{size}.png is out of date: run scripts/make_icons.py"


@pytest.mark.parametrize("size", [16, 24, 32])
def test_the_four_states_differ_in_shape_not_only_in_colour(qapp: QApplication, size: int) -> None:
    masks = {state: foreground(render(status_icon_name(state), size)) for state in ServerState}
    for a, b in itertools.combinations(ServerState, 2):
        differing = sum(x != y for x, y in zip(masks[a], masks[b], strict=True))
        assert differing >= size * size // 12, f"{a.name} and {b.name} look alike at {size} px"


def test_the_four_states_differ_in_colour(qapp: QApplication) -> None:
    tiles = {state: render(status_icon_name(state), 32).pixelColor(3, 28) for state in ServerState}
    for a, b in itertools.combinations(ServerState, 2):
        ca, cb = tiles[a], tiles[b]
        distance = abs(ca.red() - cb.red()) + abs(ca.green() - cb.green()) + abs(ca.blue() - cb.blue())
        assert distance > 90, f"{a.name} and {b.name} have nearly the same colour"


def test_status_icon_gives_a_cached_icon_of_every_size_for_every_state(qapp: QApplication) -> None:
    for state in ServerState:
        icon = status_icon(state)
        assert icon is status_icon(state)
        assert not icon.isNull()
        for size in (16, 22, 48, 256):
            pixmap = icon.pixmap(QSize(size, size))
            assert pixmap.width() == size, f"{state.name} at {size} px"
            assert opaque_share(pixmap.toImage()) > 0.6


def test_without_the_svg_engine_the_png_renderings_are_used(qapp: QApplication) -> None:
    for name in (APP_ICON, FILE_ICON, status_icon_name(ServerState.STOPPED)):
        icon = build_icon(name, use_svg=False)
        for size in PNG_SIZES:
            got = icon.pixmap(QSize(size, size)).toImage()
            assert max_difference(got, QImage(str(icon_path(name, size)))) <= 2, f"{name} {size} px"


def test_this_qt_draws_the_svgs_at_any_size(qapp: QApplication) -> None:
    assert icons.svg_icons_available()
    assert icons.app_icon().actualSize(QSize(200, 200)) == QSize(200, 200)
    assert not icons.file_icon().isNull()


def test_windows_ico_files_hold_png_images_from_16_to_256_px() -> None:
    for ico in ("moas-server.ico", "application-x-moas.ico"):
        data = (ICON_DIR / ico).read_bytes()
        reserved, kind, count = struct.unpack_from("<HHH", data)
        assert (reserved, kind) == (0, 1) and count == 7
        sides = []
        for index in range(count):
            side, _, _, _, _, bpp, length, offset = struct.unpack_from("<BBBBHHII", data, 6 + 16 * index)
            assert data[offset:offset + 8] == b"\x89PNG\r\n\x1a\n" and bpp == 32
            assert offset + length <= len(data)
            sides.append(side or 256)
        assert sides == [16, 24, 32, 48, 64, 128, 256]


def test_a_switch_fault_outranks_stopped_and_no_configuration_outranks_all() -> None:
    assert overall_state(False, True, ["unresponsive"]) is ServerState.NO_CONFIG
    assert overall_state(True, True, ["stopped", "unresponsive"]) is ServerState.UNRESPONSIVE
    assert overall_state(True, True, ["stopped"]) is ServerState.STOPPED
    assert overall_state(True, False, ["ok", "ok"]) is ServerState.NORMAL
    assert overall_state(True, False, ["ok", "connecting"]) is ServerState.UNRESPONSIVE
    assert all(DESCRIPTIONS[state] for state in ServerState)


def test_the_public_names_do_not_drift() -> None:
    assert sorted(icons.__all__) == sorted([
        "APP_ICON", "FILE_ICON", "ICON_DIR", "PNG_SIZES", "app_icon",
        "build_icon", "file_icon", "icon_path", "named_icon", "status_icon", "status_icon_name",
        "svg_icons_available"])
