"""One colour and one marker per backend, the same in every figure rbx draws (report, tosses,
explore, bench).

A library keeps one hue and its variants take darker or lighter shades of it, each with its own
marker, so two neighbours in a legend never share both colour and marker, and in greyscale the
marker still tells them apart. The colours start from Okabe & Ito's colour-blind-safe set.
A name not listed (a new backend) gets a grey shade and a marker of its own, by its position in
the sorted list of unlisted names it is drawn with.

save() is how every figure is written: PNG for the pages, SVG for print, at one resolution.
"""
import json
import os

# name: (colour, marker), in assets/backend_style.json, which the report's pages read too.
with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "assets",
                       "backend_style.json")) as _f:
    STYLE = {name: tuple(pair) for name, pair in json.load(_f).items()}
ORDER = list(STYLE)
_GREYS = ["#777777", "#AAAAAA", "#444444", "#CCCCCC"]
_MARKERS = "hpX<>dH8"


def style(name, others=()):
    """(colour, marker) of backend `name`; `others` are the names drawn with it (for unlisted
    names only)."""
    if name in STYLE:
        return STYLE[name]
    extra = sorted({n for n in others if n not in STYLE} | {name})
    k = extra.index(name)
    return _GREYS[k % len(_GREYS)], _MARKERS[k % len(_MARKERS)]


def colour(name, others=()):
    """The colour of backend `name` (see style)."""
    return style(name, others)[0]


def order(names):
    """Names in the registry's order, unlisted ones last, sorted."""
    return sorted(names, key=lambda b: (ORDER.index(b) if b in ORDER else len(ORDER), b))


def save(fig, out, name, rect=None):
    """Lays `fig` out (inside `rect`, figure fractions, when given), writes out/name.png and
    out/name.svg, and closes it."""
    import matplotlib.pyplot as plt
    if rect is None:
        fig.tight_layout()
    else:
        fig.tight_layout(rect=rect)
    for ext in ("png", "svg"):
        fig.savefig(os.path.join(out, f"{name}.{ext}"), dpi=110)
    plt.close(fig)
