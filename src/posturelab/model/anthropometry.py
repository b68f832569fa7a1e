"""Bodies of any size: anthropometric scaling and lumping links together.

:func:`body_from_anthropometry` builds a leg / thigh / HAT chain for a subject
of given height and mass from Dempster's segment parameters as tabulated by
Winter (2009), *Biomechanics and Motor Control of Human Movement*, 4th ed.,
Table 4.1 (segment mass fractions, centre-of-mass locations, radii of
gyration), with segment lengths from Winter's Fig. 4.1 (after Drillis and
Contini 1966): leg (knee–ankle) 0.246 H, thigh (hip–knee) 0.245 H, HAT
(hip–shoulder) 0.288 H. The table ships in ``posturelab/data/bmc_bsp``
(BMClab/BMC, CC BY 4.0).

As in the paper, link 1 is *both* legs locked together and link 2 both
thighs, so their masses and inertias are doubled; the feet are massless.

:func:`lump` merges consecutive links into one rigid link (the same body
with a locked joint): the paper's body lumped to two links is the ankle–hip
model common in the literature, and to one link the single inverted
pendulum.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .._validation import float_in_range
from ..errors import ParameterError, lookup
from ..parameters import HEIGHT_RANGE, MASS_RANGE
from .body import Body, BodyPreset, paper_body, register_body_preset

__all__ = ["WINTER_TABLE", "body_from_anthropometry", "lump", "one_link", "ANTHROPOMETRIC_TABLES"]

WINTER_CITATION = (
    "Winter DA (2009) Biomechanics and Motor Control of Human Movement, 4th ed., Table 4.1 "
    "(Dempster 1955) and Fig. 4.1 (Drillis & Contini 1966); table via BMClab/BMC, CC BY 4.0"
)

#: Per segment: mass fraction of body mass [-], length fraction of height [-], centre of mass
#: from the segment's LOWER end as a fraction of its length [-], radius of gyration about the
#: centre of mass as a fraction of its length [-], and how many of it the link holds.
#: Leg KJC–MMAL: CoM 0.433 from the knee (proximal) → 0.567 from the ankle.
#: Thigh GTR–KJC: CoM 0.433 from the hip (proximal) → 0.567 from the knee.
#: HAT GTR–SJC: CoM 0.626 from the hip (proximal, its lower end).
WINTER_TABLE: dict[str, tuple[float, float, float, float, int]] = {
    "leg": (0.0465, 0.246, 1 - 0.433, 0.302, 2),
    "thigh": (0.100, 0.245, 1 - 0.433, 0.323, 2),
    "torso": (0.678, 0.288, 0.626, 0.496, 1),
}

ANTHROPOMETRIC_TABLES = {"winter": (WINTER_TABLE, WINTER_CITATION)}


# HEIGHT_RANGE [m] and MASS_RANGE [kg], the heights and masses a body can be scaled to: the
# parameter table's (posturelab.parameters)


def body_from_anthropometry(height: float, mass: float, table: str = "winter",
                            gravity: float = 9.81) -> Body:
    """A leg / thigh / HAT body scaled to a subject.

    Parameters
    ----------
    height : float
        Standing height H. [m] (0.5–2.5)
    mass : float
        Body mass M. [kg] (10–300)
    table : str
        Anthropometric table; ``"winter"`` (Dempster via Winter 2009).
    gravity : float
        [m/s²]

    Returns
    -------
    Body
        Three links; the feet (about 2.9 % of M in Winter's table) are not
        part of the chain, so ``total_mass`` is about 0.971 M.
    """
    h = float_in_range("height [m]", height, *HEIGHT_RANGE, unit="m")
    m = float_in_range("mass [kg]", mass, *MASS_RANGE, unit="kg")
    rows, citation = lookup(ANTHROPOMETRIC_TABLES, table, "anthropometric table")
    names, masses, lengths, coms, inertias = [], [], [], [], []
    for name, (mass_frac, len_frac, com_frac, rg_frac, count) in rows.items():
        seg_len = len_frac * h
        seg_mass = mass_frac * m * count
        names.append(name)
        masses.append(seg_mass)
        lengths.append(seg_len)
        coms.append(com_frac * seg_len)
        inertias.append(seg_mass * (rg_frac * seg_len) ** 2)
    return Body.from_arrays(masses, lengths, coms, inertias, names=names,
                            name=f"{table} H={h:g} m M={m:g} kg", citation=citation,
                            gravity=gravity)


def lump(body: Body, groups: Sequence[Sequence[int]], name: str | None = None) -> Body:
    """Merge consecutive links into rigid links (a chain with locked joints).

    Parameters
    ----------
    body : Body
    groups : sequence of sequences of int
        Consecutive 1-based link numbers covering 1..N in order, e.g.
        ``[[1, 2], [3]]`` locks the knee of a three-link body.

    Returns
    -------
    Body
        Each new link has the summed mass, the summed length, the combined
        centre of mass and the inertia about it (parallel-axis theorem), for
        the straight posture of its parts.
    """
    flat = [i for g in groups for i in g]
    if flat != list(range(1, body.n_links + 1)) or any(len(g) == 0 for g in groups):
        raise ParameterError(
            f"groups must split links 1..{body.n_links} into consecutive non-empty runs, "
            f"got {list(map(list, groups))}"
        )
    m, l, k, inertia = body.masses, body.lengths, body.com_distances, body.inertias
    masses, lengths, coms, inertias, names = [], [], [], [], []
    for g in groups:
        idx = np.array(g) - 1
        base = np.concatenate([[0.0], np.cumsum(l[idx])[:-1]])  # lower end of each part
        pos = base + k[idx]
        mg = m[idx].sum()
        com = float(m[idx] @ pos / mg)
        masses.append(mg)
        lengths.append(float(l[idx].sum()))
        coms.append(com)
        inertias.append(float(np.sum(inertia[idx] + m[idx] * (pos - com) ** 2)))
        names.append("+".join(body.segments[i].name for i in idx))
    return Body.from_arrays(masses, lengths, coms, inertias, names=names,
                            name=name or f"{body.name} lumped {list(map(list, groups))}",
                            citation=body.citation, gravity=body.gravity)


def one_link(body: Body) -> Body:
    """``body`` with every joint locked: one rigid inverted pendulum about the ankle (the
    body of a one-link controller), with the same mass [kg], centre of mass [m] and inertia
    about the ankle [kg·m²] in the straight posture (:func:`lump`).

    Examples
    --------
    >>> import posturelab as pl
    >>> pl.model.anthropometry.one_link(pl.body_from_anthropometry(1.8, 82.0)).name
    'winter H=1.8 m M=82 kg, one link (knee and hip locked)'
    """
    if body.n_links == 1:
        return body
    locked = "knee and hip" if body.n_links == 3 else "every joint above the ankle"
    return lump(body, [list(range(1, body.n_links + 1))],
                name=f"{body.name}, one link ({locked} locked)")


register_body_preset(BodyPreset(
    "paper-2link", lambda: lump(paper_body(), [[1, 2], [3]], name="paper-2link"),
    "Appendix A body with the knee locked: the two-link ankle–hip model",
    "the paper's body with leg and thigh merged (ankle–hip model), 65.59 kg",
))
register_body_preset(BodyPreset(
    "paper-1link", lambda: lump(paper_body(), [[1, 2, 3]], name="paper-1link"),
    "Appendix A body with knee and hip locked: the single inverted pendulum",
    "the paper's body as one rigid inverted pendulum, 65.59 kg",
))
register_body_preset(BodyPreset(
    "winter-1.75m-75kg", lambda: body_from_anthropometry(1.75, 75.0),
    WINTER_CITATION, "leg/thigh/HAT for a 1.75 m, 75 kg adult scaled by Winter's table",
))
