"""One colour and one marker per backend, the same in every figure rbx draws (report, tosses,
explore, bench).

A library keeps one hue and its variants take darker or lighter shades of it, each with its own
marker, so two neighbours in a legend never share both colour and marker, and in greyscale the
marker still tells them apart. The colours start from Okabe & Ito's colour-blind-safe set.
A name not listed (a new backend) gets a grey shade and a marker of its own, by its position in
the sorted list of unlisted names it is drawn with.
"""

# name: (colour, marker)
STYLE = {
    "custom": ("#0072B2", "o"),
    "custom-seed": ("#56B4E9", "s"),
    "custom (accelerated)": ("#0072B2", "o"),
    "custom (faithful)": ("#00436B", "D"),
    "exact": ("#000000", "*"),
    "fcl": ("#E69F00", "o"),
    "fcl-hull": ("#A35F00", "s"),
    "fcl-epa": ("#F3C363", "^"),
    "fcl-indep": ("#6B4E16", "D"),
    "fcl-box": ("#FFB347", "v"),
    "libccd-mpr": ("#CC79A7", "o"),
    "libccd-epa": ("#882255", "^"),
    "libccd": ("#CC79A7", "P"),
    "bullet": ("#009E73", "o"),
    "bullet-hull": ("#00543D", "s"),
    "bullet-sat": ("#7FD4B6", "D"),
    "mujoco": ("#D55E00", "o"),
    "mujoco-hull": ("#7A2E00", "s"),
    "ode": ("#6A3D9A", "o"),
    "ode-hull": ("#B39DDB", "s"),
    "dart": ("#999933", "o"),
    "dart-hull": ("#5C5C1F", "s"),
}
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
