"""The previous model's kinematics (body frames of a chain packed by
:func:`~plannerlab.collision.chain_pack._pack`, its axes folded onto z), still read by the
sphere field (:mod:`plannerlab.collision.spheres`); every check runs
:mod:`plannerlab.collision.kinematics`.
"""

from __future__ import annotations

import math

from numba import njit

from plannerlab.collision.chain_pack import (  # the packing, and its layout
    _H_DOF,
    _H_I,
    _H_L,
    _H_NB,
    _H_NCL,
    _H_NCPL,
    _H_NOBS,
)


@njit(cache=True, nogil=True, inline="always")
def _frames_of(v, T0, parent, prism, pre, Bf):
    """Body frames (nb, 3, 4) from the chain's joint values v (n,); each joint turns (or
    slides) about its frame's z axis. Scalars, not views: a view per joint and 3-d
    indexing cost more than the arithmetic."""
    for a in range(3):
        for b in range(4):
            Bf[0, a, b] = T0[a, b]
    for i in range(parent.shape[0]):
        qi = v[i]
        f = parent[i]
        p00, p01, p02, p03 = pre[i, 0, 0], pre[i, 0, 1], pre[i, 0, 2], pre[i, 0, 3]
        p10, p11, p12, p13 = pre[i, 1, 0], pre[i, 1, 1], pre[i, 1, 2], pre[i, 1, 3]
        p20, p21, p22, p23 = pre[i, 2, 0], pre[i, 2, 1], pre[i, 2, 2], pre[i, 2, 3]
        slide = prism[i] != 0
        cq = 1.0
        sq = 0.0
        if not slide:
            cq = math.cos(qi)
            sq = math.sin(qi)
        for a in range(3):
            f0, f1, f2, f3 = Bf[f, a, 0], Bf[f, a, 1], Bf[f, a, 2], Bf[f, a, 3]
            g0 = f0 * p00 + f1 * p10 + f2 * p20
            g1 = f0 * p01 + f1 * p11 + f2 * p21
            g2 = f0 * p02 + f1 * p12 + f2 * p22
            g3 = f0 * p03 + f1 * p13 + f2 * p23
            g3 += f3
            if slide:
                g3 += qi * g2
                Bf[i + 1, a, 0] = g0
                Bf[i + 1, a, 1] = g1
            else:
                Bf[i + 1, a, 0] = cq * g0 + sq * g1
                Bf[i + 1, a, 1] = cq * g1 - sq * g0
            Bf[i + 1, a, 2] = g2
            Bf[i + 1, a, 3] = g3


@njit(cache=True, nogil=True, inline="always")
def _body_frames(q, T0, parent, prism, pre, Bf, cpl, v):
    """Body frames (nb, 3, 4) of one state q (the chain's axes are folded into ``pre`` and
    the capsules by ``_pack``). ``cpl``: the coupling's (starts, indices, coefficients),
    empty without one; with one, the chain's joint values ``Σ_k cpl_val[k] q[cpl_idx[k]]``
    go through the scratch v (n,) first (tested once here, not per joint: ~2.5 times
    faster kinematics)."""
    cpl_start, cpl_idx, cpl_val = cpl
    if cpl_start.shape[0] == 0:
        _frames_of(q, T0, parent, prism, pre, Bf)
        return
    for i in range(parent.shape[0]):
        x = 0.0
        for k in range(cpl_start[i], cpl_start[i + 1]):
            x += cpl_val[k // 3, k % 3] * q[cpl_idx[k]]
        v[i] = x
    _frames_of(v, T0, parent, prism, pre, Bf)


@njit(cache=True, nogil=True, inline="always")
def _iv(idat, k):
    """Int section k (see ``chain_pack._I_SECTIONS``), flat."""
    return idat[idat[_H_I + k] : idat[_H_I + k + 1]]


@njit(cache=True, nogil=True)
def _unpack(P, M, idat):
    """Views of the packed arrays (see ``_pack``): slices only (a reshape costs some 30 ns
    in numba, a slice about one)."""
    dof, nb, L, n, ncl = idat[_H_DOF], idat[_H_NB], idat[_H_L], idat[_H_NOBS], idat[_H_NCL]
    ncpl = idat[_H_NCPL]
    ints = (
        _iv(idat, 0),
        _iv(idat, 1),
        _iv(idat, 2),
        _iv(idat, 3),
        _iv(idat, 4),
        _iv(idat, 5),
        _iv(idat, 6),
        _iv(idat, 7),
        _iv(idat, 8),
        _iv(idat, 9),
        _iv(idat, 10),
        _iv(idat, 13),
    )
    o = 3 * L + 2 * nb + 2 * ncl  # the obstacles' rows of P
    e = o + 4 * n  # the coupling's coefficients, three a row, after the obstacles
    cpl = (_iv(idat, 11), _iv(idat, 12), P[e : e + (ncpl + 2) // 3])
    floats = (
        M[0],
        M[1 : 1 + dof],
        P[0:L],
        P[L : 2 * L],
        P[2 * L : 3 * L, 0],
        P[2 * L : 3 * L, 1],
        P[3 * L : 3 * L + nb],
        P[3 * L + nb : 3 * L + 2 * nb, 0],
        P[3 * L + nb : 3 * L + 2 * nb, 1],
        P[3 * L + 2 * nb : 3 * L + 2 * nb + ncl],
        P[3 * L + 2 * nb + ncl : o, 0],
        P[3 * L + 2 * nb + ncl : o, 1],
        M[1 + dof : 1 + dof + n, :, :3],
        P[o : o + n],
        P[o + n : o + 2 * n],
        P[o + 2 * n : o + 3 * n],
        P[o + 3 * n : o + 4 * n],
    )
    return ints, floats, cpl


__all__: list[str] = []  # the kinematics below serve spheres.py only
