"""The lateral-path optimal-control problem of the maneuver planner (CasADi, IPOPT).

The airspeed is not optimised: it is fixed at every node from the profile's q(t) schedule
(maneuvers/profiles.py), so the q target is met exactly and uniformity is by construction (a
soft q penalty hides infeasibility, docs/measured.md). What IPOPT chooses is the lateral path - bank
as a state driven by a piecewise-constant roll rate - so that the ground track stays inside the
test-area circle in the given wind, bank and roll-rate stay within limits, and the heading
turns through 360 deg inside each coverage group of nodes (what makes the wind observable).

Transcription: multiple shooting, one RK4 step per interval, written as whole-vector MX
operations over all intervals at once (a few dozen graph nodes whatever N is); variables scaled
to order one (km, rad/10). The decision, parameter and constraint vectors are addressed through
named slices (`Layout`).
"""

import time
from dataclasses import dataclass

import numpy as np

from pitotcal.core.dynamics import rhs
from pitotcal.core.errors import PitotcalError
from pitotcal.core.processes import solver_interrupts
from pitotcal.core.units import G0_MPS2

__all__ = ["TURNS", "Layout", "ManeuverProblem", "PathSolution", "group_signs", "node_signs",
           "path_rhs", "rk4_step", "turn_radius_m"]

TURN_SIGN = {"right": 1.0, "left": -1.0}
# Turn directions the OCP takes: "both" alternates right and left orbits from one coverage
# group to the next (in the order the groups are first flown), so a term that goes with the
# turn rate (a probe's lever arm) averages out.
TURNS = ("right", "left", "both")
_KM = 1000.0          # position scale
_PSI = 10.0           # heading scale (unwrapped heading reaches ~20 rad)
_P = 0.1              # roll-rate scale, rad/s
_HEADING_MARGIN_RAD = float(np.radians(15.0))
_PATH_STATES = ("north_m", "east_m", "heading_rad", "bank_rad", "tas_mps")


def turn_radius_m(tas_mps, bank_rad):
    """Radius of a steady coordinated turn in still air, V^2 / (g tan(bank))."""
    return np.asarray(tas_mps) ** 2 / (G0_MPS2 * np.tan(bank_rad))


def group_signs(groups, turn):
    """Turn sense (+1 right, -1 left) of each coverage group; "both": alternating in the order
    the groups are first flown, starting right."""
    if turn != "both":
        return np.full(len(groups), TURN_SIGN[turn])
    order = np.argsort([min(a for a, _ in runs) if runs else 0 for runs in groups])
    signs = np.empty(len(groups))
    signs[order] = np.where(np.arange(len(groups)) % 2 == 0, 1.0, -1.0)
    return signs


def node_signs(groups, signs, n_nodes):
    """The turn sense at each node: its group's, a node in no group keeps the one before (the
    first group's before any)."""
    out = np.full(n_nodes, np.nan)
    for g, runs in enumerate(groups):
        for a, b in runs:
            out[a:b + 1] = signs[g]
    first = signs[int(np.argmin([min(a for a, _ in runs) if runs else n_nodes
                                 for runs in groups]))]
    out[0] = first if np.isnan(out[0]) else out[0]
    for i in range(1, n_nodes):
        if np.isnan(out[i]):
            out[i] = out[i - 1]
    return out


class Layout:
    """Named consecutive slices of a flat vector: ``Layout(a=3, b=1)["b"] == slice(3, 4)``."""

    def __init__(self, **sizes):
        self.slices, start = {}, 0
        for name, size in sizes.items():
            self.slices[name] = slice(start, start + int(size))
            start += int(size)
        self.size = start

    def __getitem__(self, name):
        return self.slices[name]

    def index(self, name):
        """The position of a one-element entry."""
        return self.slices[name].start


def path_rhs(n):
    """Named `ca.Function` "path_rhs": the lateral path's dynamics on `n` intervals at once.

    The shared point-mass model (pitotcal.core.dynamics.rhs) with bank as a state whose rate
    is the roll-rate control. Inputs north_m, east_m, heading_rad, bank_rad, tas_mps, roll_rps,
    accel_mps2 (each n x 1) and wind_ne_mps (2 x 1, blowing TO); outputs their five rates.
    """
    import casadi as ca

    x = [ca.MX.sym(name, n) for name in _PATH_STATES]
    roll, accel, wind = ca.MX.sym("roll_rps", n), ca.MX.sym("accel_mps2", n), ca.MX.sym("wind", 2)
    d = rhs((x[0], x[1], 0, x[2], x[4]), (x[3], accel, 0), (wind[0], wind[1]), lib=ca)
    return ca.Function("path_rhs", [*x, roll, accel, wind], [d[0], d[1], d[3], roll, d[4]],
                       [*_PATH_STATES, "roll_rps", "accel_mps2", "wind_ne_mps"],
                       [f"{name}_rate" for name in _PATH_STATES], {"always_inline": True})


def rk4_step(n):
    """Named `ca.Function` "rk4_step": one RK4 step of `path_rhs` on each of `n` intervals.

    Inputs: the five path states at the interval starts, roll_rps, accel_mps2 (n x 1, constant
    on each interval), wind_ne_mps (2 x 1) and the interval lengths h_s (n x 1); outputs the
    states at the interval ends.
    """
    import casadi as ca

    f = path_rhs(n)
    x0 = [ca.MX.sym(name, n) for name in _PATH_STATES]
    roll, accel, wind = ca.MX.sym("roll_rps", n), ca.MX.sym("accel_mps2", n), ca.MX.sym("wind", 2)
    h = ca.MX.sym("h_s", n)
    k1 = f(*x0, roll, accel, wind)
    k2 = f(*[a + 0.5 * h * b for a, b in zip(x0, k1)], roll, accel, wind)
    k3 = f(*[a + 0.5 * h * b for a, b in zip(x0, k2)], roll, accel, wind)
    k4 = f(*[a + h * b for a, b in zip(x0, k3)], roll, accel, wind)
    end = [a + h / 6.0 * (b1 + 2 * b2 + 2 * b3 + b4)
           for a, b1, b2, b3, b4 in zip(x0, k1, k2, k3, k4)]
    return ca.Function("rk4_step", [*x0, roll, accel, wind, h], end,
                       [*_PATH_STATES, "roll_rps", "accel_mps2", "wind_ne_mps", "h_s"],
                       [f"{name}_end" for name in _PATH_STATES], {"always_inline": True})


@dataclass(frozen=True)
class PathSolution:
    """The lateral path found by `ManeuverProblem.solve` on the schedule's nodes.

    Attributes
    ----------
    north_m, east_m, heading_rad, bank_rad : ndarray (N + 1,)
        Ground position relative to the centre, unwrapped air-relative heading, bank.
    roll_rate_rps : ndarray (N,)
        Piecewise-constant roll rate on each interval.
    radius_m : float
        Largest distance from the centre allowed by the constraint (the minimised radius when
        solved with ``minimize_radius=True``).
    success, message, iterations, solve_time_s :
        IPOPT's outcome.
    """

    north_m: np.ndarray
    east_m: np.ndarray
    heading_rad: np.ndarray
    bank_rad: np.ndarray
    roll_rate_rps: np.ndarray
    radius_m: float
    success: bool
    message: str
    iterations: int
    solve_time_s: float


class ManeuverProblem:
    """The lateral-path OCP for one grid size; build once, solve for many schedules and winds.

    Parameters
    ----------
    n_intervals : int
        Number of shooting intervals N (nodes N + 1).
    n_groups : int
        Number of heading-coverage groups (3: the thirds of the q range; 2 for two-speed).
    ipopt_options : dict, optional
        Passed to IPOPT (``{"max_iter": 300}`` etc.), on top of quiet defaults.

    Notes
    -----
    Variables z = [north_km, east_km, psi/10, bank] at the nodes, roll rate p/0.1 on the
    intervals, and r2 (km^2), the squared radius bound. Per interval k of length h_k:

        x_{k+1} = RK4(x_k; bank' = p_k, V(t) = V_k + a_k (t - t_k), wind),
        north_k^2 + east_k^2 <= r2,       |bank_k| <= bank_max,     |p_k| <= p_max,
        sum over the runs of group g of s (psi_last - psi_first) >= 2 pi + margin,

    with s = +1 for right turns, -1 for left. Cost:
    mean((p / 0.1)^2) + 0.1 mean(bank^2) + 0.03 mean(north_km^2 + east_km^2) + w_r r2, where
    w_r = 0 with r2 fixed at (R - margin)^2 (planning) or w_r > 0 with r2 free (the smallest
    radius that fits). The q target is held exactly by the fixed V_k, so its closeness term is
    identically zero.

    Example
    -------
    >>> from pitotcal.maneuvers.plan.profiles import make_schedule
    >>> s = make_schedule("continuous", 36.0, 51.4, 240.0, altitude_m=244.0)
    >>> sol = ManeuverProblem(s.n_intervals).solve(s, 926.0, (5.0, 0.0), 0.52, 0.17)
    >>> bool(sol.success)
    True
    """

    def __init__(self, n_intervals, n_groups=3, *, ipopt_options=None):
        import casadi as ca

        n = int(n_intervals)
        if n < 2:
            raise PitotcalError(f"n_intervals {n_intervals} must be at least 2")
        self.n_intervals, self.n_groups = n, int(n_groups)
        m = n + 1
        self.x = Layout(north_km=m, east_km=m, heading=m, bank_rad=m, roll=n, r2_km2=1)
        self.p = Layout(h_s=n, tas_mps=m, accel_mps2=n, wind_ne_mps=2,
                        cover=self.n_groups * m, w_radius=1)
        self.g = Layout(defects=4 * n, radius=m, coverage=self.n_groups)
        z, par = ca.MX.sym("z", self.x.size), ca.MX.sym("p", self.p.size)
        north, east = z[self.x["north_km"]] * _KM, z[self.x["east_km"]] * _KM
        psi, bank = z[self.x["heading"]] * _PSI, z[self.x["bank_rad"]]
        roll, r2 = z[self.x["roll"]] * _P, z[self.x.index("r2_km2")]
        h, tas, accel = par[self.p["h_s"]], par[self.p["tas_mps"]], par[self.p["accel_mps2"]]
        cover = ca.reshape(par[self.p["cover"]], self.n_groups, m)
        end = rk4_step(n)(north[:-1], east[:-1], psi[:-1], bank[:-1], tas[:-1], roll, accel,
                          par[self.p["wind_ne_mps"]], h)
        defects = ca.vertcat((north[1:] - end[0]) / _KM, (east[1:] - end[1]) / _KM,
                             (psi[1:] - end[2]) / _PSI, bank[1:] - end[3])
        radius = (north / _KM) ** 2 + (east / _KM) ** 2 - r2
        coverage = ca.mtimes(cover, psi)
        # roll-rate smoothness, mild bank (paper: "mild turns"), and a weak pull to the centre
        # so the track keeps room for tracking errors instead of riding the boundary
        cost = (ca.sumsqr(roll / _P) / n + 0.1 * ca.sumsqr(bank) / m
                + 0.03 * (ca.sumsqr(north / _KM) + ca.sumsqr(east / _KM)) / m
                + par[self.p.index("w_radius")] * r2)
        opts = {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes",
                "ipopt.max_iter": 300, "ipopt.tol": 1e-7}
        for key, value in (ipopt_options or {}).items():
            opts[key if key.startswith("ipopt.") or key == "print_time" else f"ipopt.{key}"] \
                = value
        self._solver = ca.nlpsol("maneuver", "ipopt",
                                 {"x": z, "p": par, "f": cost,
                                  "g": ca.vertcat(defects, radius, coverage)}, opts)

    def solve(self, schedule, radius_m, wind_ne_mps, bank_max_rad, roll_rate_max_rps, *,
              turn="right", margin_m=1.0, heading_margin_rad=_HEADING_MARGIN_RAD,
              minimize_radius=False, guess=None):
        """Solve for the lateral path of `schedule` inside `radius_m` in the wind.

        Parameters
        ----------
        schedule : maneuvers.plan.profiles.Schedule
            With ``n_intervals`` equal to this problem's and ``len(groups) == n_groups``.
        radius_m : float
            Test-area radius; the track stays within ``radius_m - margin_m`` at every node.
        wind_ne_mps : (float, float)
            Air-mass velocity north, east (the way it blows TO), m/s.
        bank_max_rad, roll_rate_max_rps : float
            Limits.
        turn : {"right", "left", "both"}
        margin_m : float
            Radius margin: the constraint holds at the nodes, the track overshoots by < 0.1 m
            between them (docs/measured.md).
        heading_margin_rad : float
            Extra turn beyond 360 deg in each group.
        minimize_radius : bool
            Free the radius and minimise it: gives the smallest radius that fits.
        guess : PathSolution, optional
            Start from this path instead of the constant-bank circle.

        Returns
        -------
        PathSolution
        """
        n = self.n_intervals
        if schedule.n_intervals != n or len(schedule.groups) != self.n_groups:
            raise PitotcalError(f"schedule has {schedule.n_intervals} intervals and "
                                f"{len(schedule.groups)} groups; this problem was built for "
                                f"{n} and {self.n_groups}")
        sign = group_signs(schedule.groups, turn)
        r_lim = (radius_m - margin_m) / _KM
        bounds = self._bounds(bank_max_rad, roll_rate_max_rps / _P, heading_margin_rad,
                              None if minimize_radius else r_lim ** 2)
        x0 = self._guess(schedule, sign, radius_m, bank_max_rad, heading_margin_rad) \
            if guess is None else self._pack(guess)
        if not minimize_radius:
            x0[self.x["r2_km2"]] = r_lim ** 2
        tic = time.perf_counter()
        with solver_interrupts():
            out = self._solver(x0=x0, p=self._parameters(schedule, sign, wind_ne_mps,
                                                         minimize_radius), **bounds)
        elapsed = time.perf_counter() - tic
        stats = self._solver.stats()
        z = np.asarray(out["x"]).ravel()
        return PathSolution(
            north_m=z[self.x["north_km"]] * _KM, east_m=z[self.x["east_km"]] * _KM,
            heading_rad=z[self.x["heading"]] * _PSI, bank_rad=z[self.x["bank_rad"]],
            roll_rate_rps=z[self.x["roll"]] * _P,
            radius_m=float(np.sqrt(max(z[self.x.index("r2_km2")], 0.0)) * _KM),
            success=bool(stats["success"]), message=str(stats["return_status"]),
            iterations=int(stats["iter_count"]), solve_time_s=elapsed)

    def _parameters(self, schedule, sign, wind_ne_mps, minimize_radius):
        """The parameter vector: interval lengths, node TAS, accelerations, wind, the signed
        coverage matrix (column-major, as `ca.reshape` reads it), the radius weight."""
        m = self.n_intervals + 1
        cover = np.zeros((self.n_groups, m))
        for g, runs in enumerate(schedule.groups):
            for first, last in runs:
                cover[g, last] += sign[g]
                cover[g, first] -= sign[g]
        par = np.empty(self.p.size)
        par[self.p["h_s"]] = np.diff(schedule.time_s)
        par[self.p["tas_mps"]] = schedule.tas_mps
        par[self.p["accel_mps2"]] = schedule.accel_mps2
        par[self.p["wind_ne_mps"]] = wind_ne_mps
        par[self.p["cover"]] = cover.ravel(order="F")
        par[self.p["w_radius"]] = 1e3 if minimize_radius else 0.0
        return par

    def _bounds(self, bank_max_rad, p_max, heading_margin_rad, r2_fixed):
        """lbx, ubx, lbg, ubg; `r2_fixed` None frees the radius (>= 0)."""
        lbx, ubx = np.full(self.x.size, -np.inf), np.full(self.x.size, np.inf)
        lbx[self.x["bank_rad"]], ubx[self.x["bank_rad"]] = -bank_max_rad, bank_max_rad
        lbx[self.x["roll"]], ubx[self.x["roll"]] = -p_max, p_max
        r2 = self.x["r2_km2"]
        lbx[r2], ubx[r2] = (0.0, np.inf) if r2_fixed is None else (r2_fixed, r2_fixed)
        lbg, ubg = np.zeros(self.g.size), np.zeros(self.g.size)
        lbg[self.g["radius"]] = -np.inf
        lbg[self.g["coverage"]] = 2 * np.pi + heading_margin_rad
        ubg[self.g["coverage"]] = np.inf
        return {"lbx": lbx, "ubx": ubx, "lbg": lbg, "ubg": ubg}

    def _pack(self, sol):
        """The decision vector of a `PathSolution` (a warm start)."""
        z = np.empty(self.x.size)
        z[self.x["north_km"]], z[self.x["east_km"]] = sol.north_m / _KM, sol.east_m / _KM
        z[self.x["heading"]], z[self.x["bank_rad"]] = sol.heading_rad / _PSI, sol.bank_rad
        z[self.x["roll"]] = sol.roll_rate_rps / _P
        z[self.x["r2_km2"]] = (sol.radius_m / _KM) ** 2
        return z

    def _guess(self, schedule, sign, radius_m, bank_max_rad, heading_margin_rad):
        """A circle around the centre at constant bank (13-19 iterations; zeros: 177-880)."""
        tas, t = schedule.tas_mps, schedule.time_s
        # bank that keeps the fastest circle at 80 % of the radius, and that turns enough
        tan_fit = tas.max() ** 2 / (G0_MPS2 * 0.8 * radius_m)
        turn_unit = np.r_[0.0, np.cumsum(np.diff(t) * 0.5 * (1 / tas[1:] + 1 / tas[:-1]))]
        need = max(sum(turn_unit[b] - turn_unit[a] for a, b in runs)
                   for runs in schedule.groups)
        tan_cover = 1.2 * (2 * np.pi + heading_margin_rad) / (G0_MPS2 * max(need, 1e-9))
        bank = min(np.arctan(max(tan_fit, tan_cover)), 0.95 * bank_max_rad)
        # per node: the sign of the group flown (nodes between groups keep the last one)
        node_sign = node_signs(schedule.groups, sign, t.size)
        psi = G0_MPS2 * np.tan(bank) * np.r_[0.0, np.cumsum(np.diff(turn_unit)
                                                            * node_sign[1:])]
        r = turn_radius_m(tas, bank)
        return self._pack(PathSolution(
            north_m=node_sign * r * np.sin(psi), east_m=-node_sign * r * np.cos(psi),
            heading_rad=psi, bank_rad=node_sign * bank, roll_rate_rps=np.zeros(t.size - 1),
            radius_m=radius_m, success=False, message="guess", iterations=0,
            solve_time_s=0.0))
