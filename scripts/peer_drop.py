#!/usr/bin/env python3
"""Peer drops from SciPy, for the physical generator `host-tests/src/drop/`.

An independent model of what an accelerometer on a dropped body records: held at rest
(+g), released, free fall (0), contacts with gravity in them (`m z'' = m g - F(z, z')`,
specific force F/m), ballistic flights from the separation depth to the pad's recovered
surface (the virgin surface, or a two-phase pad's set, which it keeps; a two-phase pad reloads
along `kr (z - x_p) + c v` and is back on `kc z` past its deepest point). Each contact is
integrated by `scipy.integrate.solve_ivp` (DOP853, rtol 1e-12, atol 1e-16) with its events
(maximum depth, return to the virgin line, separation where the force returns to zero)
located by SciPy's root finder; the peak force is refined on the dense output.

`host-tests/tests/drop_peer.rs` renders the same cases with `impact_host::drop` and compares
every contact's quantities and the samples to 1e-6 relative; CI never runs this script.

Rerun (needs the network once):

    python3 -m venv /tmp/peer && /tmp/peer/bin/pip install scipy==1.17.1 numpy
    /tmp/peer/bin/python scripts/peer_drop.py > scripts/peer_drop.csv

Output: CSV `case,index,quantity,value` after `#` lines naming the versions and the date.
`index` is the contact (from 0) for contact quantities (`touch_s`, `approach_m_s`,
`crush_time_s`, `max_deformation_m`, `peak_force_n`, `contact_time_s`, `rebound_m_s`,
`separation_deformation_m`, `set_m`), the sample for `accel_m_s2` (sample k at k / rate).
"""

import datetime
import sys

import numpy as np
import scipy
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

G = 9.80665

# Each case: the law, the body, the start, the record (rate, samples), contacts to model,
# the samples written (every `stride`-th).
CASES = {
    # Seed 001's nonlinear law on a soft pad, from 92 mm (first approach 1.3357 m/s).
    "nonlinear-train": dict(
        law=("nonlinear", dict(k=250.0, c=0.3, n=1.0)), m=0.06,
        start=("rest", 0.02, 1.3357**2 / (2 * G)), rate=20_000.0, n=30_000,
        contacts=8, stride=97),
    # A Kelvin–Voigt pad (k 1e4 N/m, c 5 N s/m) from 91 mm after 50 ms at rest.
    "kv-rest": dict(
        law=("kelvin-voigt", dict(k=1e4, c=5.0)), m=0.06,
        start=("rest", 0.05, 0.091), rate=100_000.0, n=100_000,
        contacts=6, stride=211),
    # The seed-001 bench's two-phase pad (Table 1's x_m and x_p), which keeps its dent.
    "two-phase-seed": dict(
        law=("two-phase", dict(kc=0.06 * (1.3357 / 0.0186) ** 2, kr=12376.0, c=2.0,
                               xp=0.0182)), m=0.06,
        start=("rest", 0.01, 1.3357**2 / (2 * G)), rate=50_000.0, n=40_000,
        contacts=4, stride=89),
    # Two-phase with the set from force continuity, undamped.
    "two-phase-continuous": dict(
        law=("two-phase", dict(kc=2e4, kr=8e4, c=0.0, xp=None)), m=0.1,
        start=("rest", 0.0, 0.05), rate=100_000.0, n=60_000,
        contacts=5, stride=101),
    # A steel ball (r 6.35 mm, 8.419 g) on a steel flat: Hertz, K from the radii and moduli.
    "hertz-steel": dict(
        law=("hertz", dict(k=4.0 / 3.0 * (200e9 / (2 * (1 - 0.3**2))) * np.sqrt(6.35e-3))),
        m=8.419e-3, start=("rest", 0.001, 0.02), rate=1_000_000.0, n=150_000,
        contacts=3, stride=53),
    # A linear spring struck horizontally (no gravity, no flights).
    "linear-horizontal": dict(
        law=("linear", dict(k=5e4)), m=0.2, g=0.0,
        start=("moving", 0.003, 2.0), rate=200_000.0, n=4_000, contacts=1, stride=7),
}


class Pad:
    def __init__(self, kind, p):
        self.kind, self.p, self.deepest = kind, p, 0.0

    def set_of(self, deepest):
        p = self.p
        return p["xp"] if p["xp"] is not None else deepest * (1 - p["kc"] / p["kr"])

    def surface(self):
        if self.kind == "two-phase" and self.deepest > 0:
            return self.set_of(self.deepest)
        return 0.0

    def force(self, z, v, branch):
        """branch: ('load',) | ('reload', deepest) | ('unload', deepest)"""
        p = self.p
        if self.kind == "linear":
            return p["k"] * z
        if self.kind == "hertz":
            return p["k"] * np.sign(z) * abs(z) ** 1.5
        if self.kind == "kelvin-voigt":
            return p["k"] * z + p["c"] * v
        if self.kind == "nonlinear":
            return p["k"] * np.sign(z) * abs(z) ** p["n"] * (1 + p["c"] * v)
        # two-phase
        if branch[0] == "load":
            return p["kc"] * z
        return p["kr"] * (z - self.set_of(branch[1])) + p["c"] * v

    def first_branch(self):
        if self.kind == "two-phase" and self.deepest > 0:
            return ("reload", self.deepest)
        return ("load",)


def contact(pad, m, g, t0, z0, v0, t_end):
    """One contact from touch (t0, z0, v0): the events and the dense pieces."""
    branch = pad.first_branch()
    pieces, t, y = [], t0, np.array([z0, v0])
    out = dict(max=None, sep=None, peak=pad.force(z0, v0, branch))
    while t < t_end:
        br = branch

        def rhs(_t, y):
            return [y[1], g - pad.force(y[0], y[1], br) / m]

        evs = []
        if out["max"] is None:
            e_max = lambda _t, y: y[1]
            e_max.terminal, e_max.direction = True, -1
            evs.append(("max", e_max))
            if br[0] == "reload":
                e_vir = lambda _t, y: y[0] - br[1]
                e_vir.terminal, e_vir.direction = True, 1
                evs.append(("virgin", e_vir))
        else:
            e_sep = lambda _t, y: pad.force(y[0], y[1], br)
            e_sep.terminal, e_sep.direction = True, -1
            evs.append(("sep", e_sep))
        sol = solve_ivp(rhs, (t, t_end), y, method="DOP853", rtol=1e-12, atol=1e-16,
                        dense_output=True, events=[e for _, e in evs])
        pieces.append((t, sol.t[-1], sol.sol, br))
        # Peak force on this piece: the grid's largest, refined.
        grid = np.linspace(t, sol.t[-1], 20001)
        zs, vs = sol.sol(grid)
        f = np.array([pad.force(a, b, br) for a, b in zip(zs, vs)])
        i = int(np.argmax(f))
        lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
        if hi > lo:
            r = minimize_scalar(lambda s: -pad.force(*sol.sol(s), br), bounds=(lo, hi),
                                method="bounded", options=dict(xatol=1e-15))
            out["peak"] = max(out["peak"], f[i], -r.fun)
        else:
            out["peak"] = max(out["peak"], f[i])
        hit = [(name, ts[0], ys[0]) for (name, _), ts, ys in
               zip(evs, sol.t_events, sol.y_events) if len(ts)]
        if not hit:
            break
        name, t, y = min(hit, key=lambda h: h[1])
        if name == "max":
            out["max"] = (t, y[0])
            branch = ("unload", y[0]) if br[0] == "load" else ("unload", br[1])
            out["peak"] = max(out["peak"], pad.force(y[0], y[1], branch))
        elif name == "virgin":
            branch = ("load",)
        else:
            out["sep"] = (t, y[0], y[1])
            break
    return out, pieces


def render(case):
    kind, p = case["law"]
    m, g = case["m"], case.get("g", G)
    rate, n = case["rate"], case["n"]
    times = np.arange(n) / rate
    accel = np.full(n, np.nan)
    pad = Pad(kind, p)
    if case["start"][0] == "rest":
        _, rest, h = case["start"]
        accel[times < rest] = g
        t_touch, v_touch = rest + np.sqrt(2 * h / g), np.sqrt(2 * g * h)
        accel[(times >= rest) & (times < t_touch)] = 0.0
    else:
        _, t_touch, v_touch = case["start"]
        accel[times < t_touch] = 0.0
    rows, z_touch, end = [], 0.0, n / rate
    for k in range(case["contacts"]):
        out, pieces = contact(pad, m, g, t_touch, z_touch, v_touch, end)
        for a, b, sol, br in pieces:
            sel = (times >= a) & (times <= b) & np.isnan(accel)
            zs, vs = sol(times[sel])
            accel[sel] = [max(0.0, pad.force(z, v, br)) / m for z, v in zip(zs, vs)]
        row = dict(touch_s=t_touch, approach_m_s=v_touch, peak_force_n=out["peak"])
        if out["max"]:
            row.update(crush_time_s=out["max"][0] - t_touch,
                       max_deformation_m=out["max"][1] - z_touch)
            pad.deepest = max(pad.deepest, out["max"][1])
        rows.append(row)
        if not out["sep"]:
            break
        ts, zs, vs = out["sep"]
        surface = pad.surface()
        row.update(contact_time_s=ts - t_touch, rebound_m_s=-vs,
                   separation_deformation_m=zs - z_touch, set_m=surface - z_touch)
        if g == 0:
            accel[times > ts] = 0.0
            break
        rise = vs * vs - 2 * g * (zs - surface)
        flight = (-vs + np.sqrt(rise)) / g
        t_land = ts + flight
        accel[(times > ts) & (times < t_land)] = 0.0
        t_touch, z_touch, v_touch = t_land, surface, np.sqrt(rise)
        if t_touch >= end:
            break
    return rows, accel


def main():
    w = sys.stdout.write
    w(f"# scipy {scipy.__version__}, numpy {np.__version__}, python {sys.version.split()[0]}\n")
    w(f"# written {datetime.date.today().isoformat()} by scripts/peer_drop.py\n")
    w("case,index,quantity,value\n")
    for name, case in CASES.items():
        rows, accel = render(case)
        for i, row in enumerate(rows):
            for q, v in row.items():
                w(f"{name},{i},{q},{v:.17g}\n")
        for k in range(0, len(accel), case["stride"]):
            if not np.isnan(accel[k]):
                w(f"{name},{k},accel_m_s2,{accel[k]:.17g}\n")


if __name__ == "__main__":
    main()
