#!/usr/bin/env python3
"""Independent reference implementation (numpy + scipy) of three curve
parameterization methods, producing params_golden.json for scanfit tests.

Methods:
  universal : uniform clamped knots, params = argmax of each basis function (Lim 1999)
  hybrid    : chord-length params -> averaging knots -> B_i = max N_{i,p};
              params from normalized cumulative sqrt(|B_i - B_{i-1}|)
  proposed  : exponential params (a=0.8) -> averaging knots U -> theta_i = argmax N_{i,p};
              pairs (2i-1, 2i) shifted so their mean equals the mean of their thetas

Basis maxima: scipy BSpline with unit coefficient vector, dense sampling over the
support to bracket the maximum, then brentq on the derivative (BSpline.derivative()).
Values are cross-checked against an independent Cox-de Boor evaluation.

Run from the repository root:
    python3 crates/scanfit/tests/data/golden/make_param_golden.py
"""
import json
import os

import numpy as np
import scipy
from scipy.interpolate import BSpline
from scipy.optimize import brentq

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", "..", "..", "..", ".."))
DATA = os.path.join(ROOT, "examples", "data")
EPS = np.finfo(float).eps
NSAMP = 20001


def load(k):
    pts = np.loadtxt(os.path.join(DATA, f"dataset{k}.csv"), delimiter=",", skiprows=1)
    return np.atleast_2d(pts)


def exp_params(pts, a):
    d = np.diff(pts, axis=0)
    di = np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2])
    w = di ** a
    cs = np.cumsum(w)
    u = np.empty(len(pts))
    u[0] = 0.0
    u[1:] = cs / cs[-1]
    u[-1] = 1.0
    return u


def averaging_knots(u, p):
    n = len(u) - 1
    inner = [(1.0 / p) * np.sum(u[j:j + p]) for j in range(1, n - p + 1)]
    return np.concatenate([np.zeros(p + 1), np.array(inner, dtype=float), np.ones(p + 1)])


def uniform_knots(n, p):
    inner = [j / (n + 1 - p) for j in range(1, n - p + 1)]
    return np.concatenate([np.zeros(p + 1), np.array(inner, dtype=float), np.ones(p + 1)])


def cox_de_boor(t, p, i, x):
    """Independent scalar evaluation of N_{i,p}(x) (right end of domain included)."""
    m = len(t) - 1
    # degree-0 functions
    N = np.zeros(m)
    last = m - p - 1  # last nonempty span index for the domain end
    for j in range(m):
        if t[j] <= x < t[j + 1]:
            N[j] = 1.0
    if x >= t[-1]:
        # x == 1: use last nonzero-length span
        j = m - 1
        while t[j] >= t[j + 1]:
            j -= 1
        N[:] = 0.0
        N[j] = 1.0
    for k in range(1, p + 1):
        Nn = np.zeros(m - k)
        for j in range(m - k):
            v = 0.0
            den1 = t[j + k] - t[j]
            den2 = t[j + k + 1] - t[j + 1]
            if den1 > 0:
                v += (x - t[j]) / den1 * N[j]
            if den2 > 0:
                v += (t[j + k + 1] - x) / den2 * N[j + 1]
            Nn[j] = v
        N = Nn
    del last
    return N[i]


def basis_max(t, p, i, n):
    """Return (theta, B, |N'(theta)|, note) for N_{i,p} on knots t, n+1 functions."""
    if i == 0:
        return 0.0, 1.0, 0.0, "clamped start"
    if i == n:
        return 1.0, 1.0, 0.0, "clamped end"
    c = np.zeros(n + 1)
    c[i] = 1.0
    spl = BSpline(t, c, p, extrapolate=False)
    dspl = spl.derivative()
    a, b = t[i], t[i + p + 1]
    xs = np.linspace(a, b, NSAMP)
    vals = np.nan_to_num(spl(xs))
    k = int(np.argmax(vals))
    if k == 0 or k == NSAMP - 1:
        # maximum at the support boundary (only possible at clamped domain end)
        x = xs[k]
        return float(x), float(vals[k]), float(abs(np.nan_to_num(dspl(x)))), "support end"
    # find a sign change of N' near k: N'(lo) > 0 >= N'(hi)
    lo, hi = xs[k - 1], xs[k + 1]
    dlo, dhi = float(dspl(lo)), float(dspl(hi))
    dk = float(dspl(xs[k]))
    if dk == 0.0:
        theta = float(xs[k])
    elif dlo > 0 and dk < 0:
        theta = brentq(lambda x: float(dspl(x)), lo, xs[k], xtol=1e-16, rtol=4 * EPS, maxiter=500)
    elif dk > 0 and dhi < 0:
        theta = brentq(lambda x: float(dspl(x)), xs[k], hi, xtol=1e-16, rtol=4 * EPS, maxiter=500)
    elif dhi == 0.0:
        theta = float(hi)
    elif dlo == 0.0:
        theta = float(lo)
    else:
        raise RuntimeError(f"no derivative sign change bracketing max of N_{i},{p}: {dlo} {dk} {dhi}")
    B = float(spl(theta))
    # polish: compare with neighbours at ulp scale (guard against brentq side)
    return float(theta), B, float(abs(dspl(theta))), "interior"


def all_maxima(t, p, n):
    thetas, Bs, notes, dmax = [], [], [], 0.0
    for i in range(n + 1):
        th, B, dn, note = basis_max(t, p, i, n)
        # independent check of value with Cox-de Boor
        Bc = cox_de_boor(t, p, i, th)
        assert abs(Bc - B) < 1e-13, (i, B, Bc)
        # check that nothing on a fine grid exceeds B
        if 0 < i < n:
            xs = np.linspace(t[i], t[i + p + 1], 4001)
            c = np.zeros(n + 1)
            c[i] = 1.0
            v = np.nan_to_num(BSpline(t, c, p, extrapolate=False)(xs))
            assert v.max() <= B + 1e-14, (i, v.max(), B)
            # derivative relative to local scale: N' ~ 1/h, tolerance scaled
            h = t[i + p + 1] - t[i]
            assert dn * h < 1e-9, (i, dn, h)
            dmax = max(dmax, dn * h)
        thetas.append(th)
        Bs.append(B)
        notes.append(note)
    return np.array(thetas), np.array(Bs), notes, dmax


def universal(pts, p):
    n = len(pts) - 1
    t = uniform_knots(n, p)
    th, B, notes, dm = all_maxima(t, p, n)
    u = th.copy()
    u[0], u[-1] = 0.0, 1.0
    return u, t, th, B, dm


def hybrid(pts, p):
    n = len(pts) - 1
    uc = exp_params(pts, 1.0)
    t = averaging_knots(uc, p)
    th, B, notes, dm = all_maxima(t, p, n)
    thr = 64 * EPS * np.max(B)
    dB = np.abs(np.diff(B))
    dB[dB <= thr] = 0.0
    s = np.sqrt(dB)
    tot = np.sum(s)
    u = np.empty(n + 1)
    u[0] = 0.0
    for i in range(1, n):
        u[i] = u[i - 1] + s[i - 1] / tot
    u[n] = 1.0
    return u, t, th, B, dm


def proposed(pts, p):
    n = len(pts) - 1
    u = exp_params(pts, 0.8)
    t = averaging_knots(u, p)
    th, B, notes, dm = all_maxima(t, p, n)
    u = u.copy()
    npairs = n // 2  # n even: n/2 ; n odd: (n-1)/2
    for i in range(1, npairs + 1):
        a, b = 2 * i - 1, 2 * i
        s = (th[a] + th[b]) / 2.0 - (u[a] + u[b]) / 2.0
        u[a] += s
        u[b] += s
    u[0], u[n] = 0.0, 1.0
    return u, t, th, B, dm


def main():
    cases = []
    rows = []
    for k in range(1, 7):
        pts = load(k)
        for p in (2, 3):
            for name, fn in (("universal", universal), ("hybrid", hybrid), ("proposed", proposed)):
                u, t, th, B, dm = fn(pts, p)
                gaps = np.diff(u)
                inc = bool(np.all(gaps > 0))
                case = {
                    "dataset": k, "degree": p, "method": name,
                    "params": [float(x) for x in u],
                    "knots": [float(x) for x in t],
                    "theta": [float(x) for x in th],
                    "B": [float(x) for x in B],
                    "strictly_increasing": inc,
                }
                if not inc:
                    bad = [int(j) for j in np.nonzero(gaps <= 0)[0]]
                    case["note"] = ("params not strictly increasing: u[j+1] <= u[j] for j in "
                                    f"{bad}")
                cases.append(case)
                rows.append((k, p, name, len(u), float(gaps.min()), int(np.argmin(gaps)), inc, dm))
    out = {
        "generator": {
            "scipy": scipy.__version__,
            "numpy": np.__version__,
            "command": "python3 crates/scanfit/tests/data/golden/make_param_golden.py",
        },
        "cases": cases,
    }
    with open(os.path.join(HERE, "params_golden.json"), "w") as f:
        json.dump(out, f, indent=1)
        f.write("\n")
    print(f"{'ds':>2} {'p':>1} {'method':<9} {'npts':>4} {'min_gap':>12} {'at':>3} {'incr':>5} {'max|dN|*h':>10}")
    for k, p, name, npts, g, j, inc, dm in rows:
        print(f"{k:>2} {p:>1} {name:<9} {npts:>4} {g:12.4e} {j:>3} {str(inc):>5} {dm:10.2e}")


if __name__ == "__main__":
    main()
