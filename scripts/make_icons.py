"""Render the SVG icons of ``moas_gui/resources/icons`` into their PNG and ICO fallbacks.

The SVG files are the drawings; everything else is made from them here with
Qt's own SVG renderer and committed, so a computer whose Qt lacks the SVG
plugin still gets crisp icons:

- ``<name>-<size>.png`` for every SVG at 16, 22, 24, 32, 48, 64, 128 and 256 px;
- ``moas-server.ico`` (from ``moas-normal.svg``) and ``application-x-moas.ico``
  for Windows' registry (``DefaultIcon`` needs an .ico), holding the PNGs of
  16 to 256 px;
- with ``--sheet FILE``, a contact sheet of every icon at every size on a light
  and a dark background, to look at the icons while drawing them.

Run after changing an SVG: ``.venv/bin/python scripts/make_icons.py``.
"""

from __future__ import annotations

import argparse
import os
import struct
import sys
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from PySide6.QtCore import QBuffer, QByteArray, QIODevice, QRectF, Qt
from PySide6.QtGui import QColor, QGuiApplication, QImage, QPainter
from PySide6.QtSvg import QSvgRenderer

ICONS = Path(__file__).resolve().parent.parent / "moas_gui" / "resources" / "icons"
SIZES = (16, 22, 24, 32, 48, 64, 128, 256)
ICO_SIZES = (16, 24, 32, 48, 64, 128, 256)
ICO_SOURCES = {"moas-server.ico": "moas-normal.svg",
               "application-x-moas.ico": "application-x-moas.svg"}


def render(svg: Path, size: int) -> QImage:
    """The SVG drawn into a transparent ``size`` x ``size`` image."""
    renderer = QSvgRenderer(str(svg))
    if not renderer.isValid():
        raise SystemExit(f"{svg}: Qt cannot read this SVG")
    image = QImage(size, size, QImage.Format.Format_ARGB32)
    image.fill(Qt.GlobalColor.transparent)
    painter = QPainter(image)
    painter.setRenderHint(QPainter.RenderHint.Antialiasing)
    renderer.render(painter, QRectF(0, 0, size, size))
    painter.end()
    return image


def png_bytes(image: QImage) -> bytes:
    data = QByteArray()
    buffer = QBuffer(data)
    buffer.open(QIODevice.OpenModeFlag.WriteOnly)
    image.save(buffer, "PNG")
    buffer.close()
    return bytes(data.data())


def ico_bytes(images: list[tuple[int, bytes]]) -> bytes:
    """An .ico holding PNG images (read by Windows since Vista)."""
    header = struct.pack("<HHH", 0, 1, len(images))
    offset = len(header) + 16 * len(images)
    entries = b""
    payload = b""
    for size, png in images:
        side = 0 if size >= 256 else size
        entries += struct.pack("<BBBBHHII", side, side, 0, 0, 1, 32, len(png), offset)
        payload += png
        offset += len(png)
    return header + entries + payload


def write_if_changed(path: Path, data: bytes) -> bool:
    if path.exists() and path.read_bytes() == data:
        return False
    path.write_bytes(data)
    return True


def make_all() -> list[Path]:
    """Write every PNG and ICO; return the files that changed."""
    changed: list[Path] = []
    for svg in sorted(ICONS.glob("*.svg")):
        for size in SIZES:
            target = ICONS / f"{svg.stem}-{size}.png"
            if write_if_changed(target, png_bytes(render(svg, size))):
                changed.append(target)
    for ico, source in ICO_SOURCES.items():
        images = [(size, png_bytes(render(ICONS / source, size))) for size in ICO_SIZES]
        if write_if_changed(ICONS / ico, ico_bytes(images)):
            changed.append(ICONS / ico)
    return changed


def contact_sheet(path: Path) -> None:
    """Every SVG at every size, light background above, dark below, and 16 px magnified."""
    svgs = sorted(ICONS.glob("*.svg"))
    pad, zoom = 8, 6
    row = 256 + pad
    width = pad + sum(size + pad for size in SIZES) + 16 * zoom + pad
    sheet = QImage(width, 2 * len(svgs) * row + pad, QImage.Format.Format_ARGB32)
    painter = QPainter(sheet)
    for shade, background in enumerate(("#f2f2f2", "#2b2b2b")):
        for index, svg in enumerate(svgs):
            y = pad + (shade * len(svgs) + index) * row
            painter.fillRect(0, y - pad // 2, width, row, QColor(background))
            x = pad
            for size in SIZES:
                painter.drawImage(x, y, render(svg, size))
                x += size + pad
            painter.drawImage(x, y, render(svg, 16).scaled(
                16 * zoom, 16 * zoom, Qt.AspectRatioMode.IgnoreAspectRatio,
                Qt.TransformationMode.FastTransformation))
    painter.end()
    sheet.save(str(path))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sheet", type=Path, help="also write a contact sheet PNG to this path")
    args = parser.parse_args()
    app = QGuiApplication(sys.argv[:1])  # noqa: F841 (Qt needs one for images and fonts)
    changed = make_all()
    for path in changed:
        print(f"wrote {path.relative_to(ICONS.parent.parent.parent)}")
    if not changed:
        print("every PNG and ICO is up to date")
    if args.sheet:
        contact_sheet(args.sheet)
        print(f"contact sheet: {args.sheet}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
