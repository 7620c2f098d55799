"""Renders a picture of every drawer of the drawer suite (docs/drawers/*.png) and a contact sheet.

Run: ``python scripts/render_drawers.py [--out docs/drawers]``.
"""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from lerobot_mtdagger.envs.drawers.catalogue import HELDOUT_DRAWERS, TRAINING_DRAWERS
from lerobot_mtdagger.envs.drawers.pictures import render_drawer_picture

logger = logging.getLogger(__name__)


def contact_sheet(pictures: list[tuple[str, np.ndarray]], columns: int = 5) -> Image.Image:
    """Tiles labelled pictures into one image."""
    height, width = pictures[0][1].shape[:2]
    label = 18
    rows = (len(pictures) + columns - 1) // columns
    sheet = Image.new("RGB", (columns * width, rows * (height + label)), "white")
    draw = ImageDraw.Draw(sheet)
    for index, (name, picture) in enumerate(pictures):
        x, y = (index % columns) * width, (index // columns) * (height + label)
        sheet.paste(Image.fromarray(picture), (x, y + label))
        draw.text((x + 4, y + 3), name, fill="black")
    return sheet


def main() -> None:
    """Writes one PNG per drawer and ``suite.png``."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", type=Path, default=Path("docs/drawers"))
    args = parser.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    args.out.mkdir(parents=True, exist_ok=True)
    pictures = []
    for variant in TRAINING_DRAWERS + HELDOUT_DRAWERS:
        picture = render_drawer_picture(variant)
        Image.fromarray(picture).save(args.out / f"{variant.name}.png")
        heldout = " (held out)" if variant in HELDOUT_DRAWERS else ""
        pictures.append((variant.name + heldout, picture))
        logger.info("wrote %s", args.out / f"{variant.name}.png")
    contact_sheet(pictures).save(args.out / "suite.png")
    logger.info("wrote %s", args.out / "suite.png")


if __name__ == "__main__":
    main()
