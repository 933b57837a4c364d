"""Redraw the README's small figures: one command per paper, each plot shrunk to a thumbnail.

Run from the repository's root: ``python docs/figures/draw.py``. Each figure is what the command
beside it in the README draws at full size (``--plot FILE``); this script runs exactly those
commands through the command line's own entry point and only scales the images down, so a figure
here is never drawn differently from what a user gets.
"""

import sys
import tempfile
from pathlib import Path

from PIL import Image

from htetro_opt.cli import main

HERE = Path(__file__).resolve().parent
BOX = (480, 320)  # pixels at most: a README table cell, two-panel figures still legible

# file name -> the command's arguments (the README's "run it" column, with --plot added)
FIGURES = {
    "quickstart.png": ["plan", "three_slit"],
    "cheng2020.png": ["plan", "three_slit", "--method", "htetro-ga", "--seed", "0"],
    "do2021.png": ["plan", "maze", "--method", "heat"],
    "nazarahari2019.png": ["plan", "ega_cross4", "--method", "ega", "--seed", "0"],
    "le2018.png": ["sequence", "tiling_11x11"],
    "cheng2019.png": ["cover", "coverage_16x16"],
}


def draw(name: str, argv: list[str]) -> None:
    with tempfile.TemporaryDirectory() as folder:
        full = Path(folder) / name
        code = main([*argv, "--quiet", "--plot", str(full)])
        if code != 0:
            raise SystemExit(f"{' '.join(argv)} exited with {code}")
        with Image.open(full) as image:
            image.thumbnail(BOX)  # keeps the aspect ratio
            image.save(HERE / name, optimize=True)
    print(f"{name}: htetro-opt {' '.join(argv)}")


if __name__ == "__main__":
    wanted = sys.argv[1:] or list(FIGURES)
    for name in wanted:
        draw(name, FIGURES[name])
