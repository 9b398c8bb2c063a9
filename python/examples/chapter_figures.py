"""Renders the chapter's figures (the example scenes named fig-*) into one matplotlib grid.

    python python/examples/chapter_figures.py [OUT.png]

writes the grid to OUT.png (default chapter-figures.png); with no display it needs only
matplotlib's Agg back end.
"""

import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import fourfold  # noqa: E402


def main(out: str = "chapter-figures.png", size: int = 256) -> None:
    figures = [(name, about) for name, about in fourfold.examples() if name.startswith("fig-")]
    columns = 2
    rows = (len(figures) + columns - 1) // columns
    fig, axes = plt.subplots(rows, columns, figsize=(4 * columns, 4.4 * rows), squeeze=False)
    for ax in axes.flat:
        ax.axis("off")
    for ax, (name, about) in zip(axes.flat, figures):
        picture = fourfold.render(fourfold.Scene.example(name), size=(size, size))
        ax.imshow(picture)
        ax.set_title(name, fontsize=11)
        ax.text(0.5, -0.04, about.split(":")[0], transform=ax.transAxes, ha="center", va="top", fontsize=7, wrap=True)
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    print(f"wrote {out} ({len(figures)} figures)")


if __name__ == "__main__":
    main(*sys.argv[1:2])
