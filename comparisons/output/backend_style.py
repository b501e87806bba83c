"""One colour and one marker per backend, the same in every figure rbx draws (report, tosses,
explore, bench).

A library keeps one hue and its variants take darker or lighter shades of it, each with its own
marker, so two neighbours in a legend never share both colour and marker, and in greyscale the
marker still tells them apart. The colours start from Okabe & Ito's colour-blind-safe set.
Each backend's style is its registry entry's (reference/backend.h): rbx hands the table to every
figure script in RBX_BACKEND_STYLE; a script run from Python takes it from the rbx module.
A name not listed (a backend without a style) gets a grey shade and a marker of its own, by its position in
the sorted list of unlisted names it is drawn with.

save() is how every figure is written: PNG for the pages, SVG for print, at one resolution.
"""
import json
import os



def _registry_styles():
    """name: (colour, marker), in registry order."""
    text = os.environ.get("RBX_BACKEND_STYLE")
    if text:
        return {name: tuple(pair) for name, pair in json.loads(text).items()}
    import rbx  # a script run from Python, with the rbx module importable
    return {b["name"]: (b["colour"], b["marker"]) for b in rbx.backends() if b["colour"]}


STYLE = _registry_styles()
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
