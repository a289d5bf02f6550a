"""Draws HelpSource/Guides/KineticFriction-Mouse-axes.png: the surface's +x and +y for a mouse
held as usual (cable away from the user), and the profile's swapXY, signX, signY for the mouse
turned in the puck. The axes are those of DeviceSpec::countsToMm; HID mice report +x to their
right and +y towards their back (the screen's downward), so with no swap and no signs the
surface's +y points towards the user.

Usage: /usr/bin/python3 scripts/help/draw_mouse_axes.py  (Debian's matplotlib; rewrites the PNG)"""
import math
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.transforms as transforms  # noqa: E402
from matplotlib.patches import FancyArrowPatch, FancyBboxPatch  # noqa: E402

OUT = pathlib.Path(__file__).resolve().parents[2] / "HelpSource" / "Guides" / "KineticFriction-Mouse-axes.png"

# (cable direction as an angle from "away from the user", degrees clockwise seen from above,
#  label, swapXY, signX, signY): the mouse's own axes turned with it, read on the surface's.
TURNS = [(0, "cable away from you", 0, 1, 1), (90, "cable to your right", 1, -1, 1),
         (180, "cable towards you", 0, -1, -1), (270, "cable to your left", 1, 1, -1)]


def rotate(dx, dy, degrees):
    """A direction drawn with +y up on the page, turned clockwise as seen from above."""
    a = math.radians(degrees)
    return dx * math.cos(a) + dy * math.sin(a), -dx * math.sin(a) + dy * math.cos(a)


def mouse(ax, cx, cy, degrees, size):
    """A mouse seen from above, its cable leaving its front, turned `degrees` clockwise."""
    w, h = 0.55 * size, 0.9 * size
    body = FancyBboxPatch((-w / 2, -h / 2), w, h, boxstyle=f"round,pad=0,rounding_size={0.25 * size}",
                          fc="#dddddd", ec="black", lw=1.2)
    body.set_transform(transforms.Affine2D().rotate_deg(-degrees).translate(cx, cy) + ax.transData)
    ax.add_patch(body)
    fx, fy = rotate(0, h / 2, degrees)
    ex, ey = rotate(0, h / 2 + 0.6 * size, degrees)
    ax.plot([cx + fx, cx + ex], [cy + fy, cy + ey], color="black", lw=1.5)  # the cable
    bx, by = rotate(0, h / 2, degrees)
    ax.plot([cx + bx * 0.25, cx + bx], [cy + by * 0.25, cy + by], color="black", lw=0.8)  # between the buttons


def arrow(ax, x0, y0, dx, dy, label, color):
    ax.add_patch(FancyArrowPatch((x0, y0), (x0 + dx, y0 + dy), arrowstyle="-|>", mutation_scale=18, lw=2,
                                 color=color))
    ax.text(x0 + dx * 1.18, y0 + dy * 1.18, label, color=color, ha="center", va="center", fontsize=12,
            fontweight="bold")


def main():
    fig, ax = plt.subplots(figsize=(10, 5.2), dpi=100)
    ax.set_xlim(0, 10)
    ax.set_ylim(0, 5.2)
    ax.set_aspect("equal")
    ax.axis("off")

    # The surface as seen from above, the user below it.
    ax.add_patch(FancyBboxPatch((0.3, 0.9), 3.8, 3.9, boxstyle="round,pad=0,rounding_size=0.1", fc="#f4f1e8",
                                ec="#999999"))
    ax.text(2.2, 4.95, "the surface, seen from above", ha="center", fontsize=11)
    mouse(ax, 2.2, 2.9, 0, 1.0)
    arrow(ax, 2.2, 2.9, 1.3, 0, "+x", "#c0392b")
    arrow(ax, 2.2, 2.9, 0, -1.3, "+y", "#1f5fa8")
    ax.text(2.2, 0.45, "you (the user) sit here", ha="center", fontsize=11)
    ax.text(2.2, 0.15, "no swap, no signs: +x to your right, +y towards you", ha="center", fontsize=9)

    # The mouse turned in the puck: what the profile says.
    ax.text(7.2, 4.95, "the mouse turned in the puck: its profile", ha="center", fontsize=11)
    for i, (degrees, label, swap, sx, sy) in enumerate(TURNS):
        cx, cy = 5.7 + 3.0 * (i % 2), 3.75 - 2.05 * (i // 2)
        mouse(ax, cx, cy, degrees, 0.55)
        ax.text(cx, cy - 0.78, label, ha="center", fontsize=9)
        ax.text(cx, cy - 1.05, f"swapXY {swap}, signX {sx}, signY {sy}", ha="center", fontsize=9,
                family="monospace")
    fig.savefig(OUT, bbox_inches="tight", facecolor="white")
    print(OUT)


if __name__ == "__main__":
    main()
