"""The Python interface: validate, set up, call the compiled driver, summarise."""
import dataclasses
import math
import numbers
import time

import numpy as np

from . import diagnostics, initial, physics, problems, shapes
from . import initial as _initial_module  # ``initial`` is also simulate's keyword
from . import integrate as _integrate
from .config import (
    DEFAULT_ATOL, DEFAULT_LENGTH_TOL, DEFAULT_MAX_STEPS, DEFAULT_N,
    DEFAULT_PERTURBATION, DEFAULT_RTOL, DEFAULT_SEED, DEFAULT_STEADY_INTERVAL, DEFAULT_T_END,
    DEFAULT_W,
)

#: Summary fields, in order; they are also the ensemble table's columns.
SUMMARY_FIELDS = (
    "g0", "theta0_deg", "n", "q0", "t_end", "rtol", "atol", "w", "perturbation",
    "seed", "status", "t_final", "steps_accepted", "steps_rejected", "rhs_evals",
    "wall_s", "theta_final_deg", "q_final", "aspect_ratio", "axis_ratio", "u_x",
    "u_y", "u_z", "settling_angle_deg", "tension_max", "tension_min",
    "s_tension_max", "length_error",
)


def stability_parameter(g0, theta_deg):
    """q = g0 sin θ / 3 (paper §4)."""
    return g0 * math.sin(math.radians(theta_deg)) / 3.0


# ---- input validation: one-line messages naming the value -----------------
def check_real(name, value, low=-math.inf, high=math.inf, low_open=False):
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(f"{name} must be a real number, got {value!r}")
    value = float(value)
    too_low = value <= low if low_open else value < low
    if not math.isfinite(value) or too_low or value > high:
        bound = "(" if low_open else "["
        raise ValueError(f"{name} must be finite and in {bound}{low}, {high}], got {value!r}")
    return value


def check_integer(name, value, low):
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < low:
        raise ValueError(f"{name} must be an integer >= {low}, got {value!r}")
    return int(value)


@dataclasses.dataclass
class SimulationResult:
    """One trajectory: inputs, snapshots, terminal diagnostics and run statistics.

    ``x[i]`` (3, 2n+1) are the position coefficients at ``t[i]`` and
    ``multiplier[i]`` (2n+1) the tension multiplier T there (``spectral``
    layout); ``tension_profile(i)`` gives the physical axial force N(s).
    """

    inputs: dict
    t: np.ndarray
    x: np.ndarray
    u: np.ndarray
    multiplier: np.ndarray
    status: str
    status_code: int
    t_final: float
    steps_accepted: int
    steps_rejected: int
    rhs_evals: int
    wall_s: float
    length_error_max: float  # largest |relative length error| at accepted steps
    initial_info: dict = None  # diagnostics of a given initial shape (``shapes``), else None

    @property
    def ok(self):
        return self.status_code in _integrate.SUCCESS

    @property
    def stop_reason(self):
        """'t_end', 'steady' (early stop at the terminal state) or the failure."""
        return _integrate.STOP_REASONS[self.status_code]

    @property
    def x_final(self):
        return self.x[-1]

    def tension_profile(self, i=-1):
        """(s, N(s)) at snapshot i."""
        return diagnostics.tension_profile(self.x[i], self.multiplier[i])

    def summary(self):
        """Dict with exactly the keys of ``SUMMARY_FIELDS``."""
        return terminal_summary(
            self.inputs, self.x[-1], self.u[-1], self.multiplier[-1], status=self.status,
            t_final=self.t_final, steps_accepted=self.steps_accepted,
            steps_rejected=self.steps_rejected, rhs_evals=self.rhs_evals, wall_s=self.wall_s,
        )


def terminal_summary(inputs, x, u, multiplier, **run_stats):
    """Summary fields of a final shape x with velocity u and multiplier T.

    ``inputs``: g0, theta0_deg, n, t_end, rtol, atol, w, perturbation, seed;
    ``run_stats``: status, t_final, steps_accepted, steps_rejected, rhs_evals, wall_s.
    """
    theta = diagnostics.tilt_deg(x)
    t_max, t_min, s_max = diagnostics.tension_extremes(x, multiplier)
    com_velocity = u[:, 0]
    values = dict(inputs, **run_stats)
    values.update(
        q0=stability_parameter(inputs["g0"], inputs["theta0_deg"]), theta_final_deg=theta,
        q_final=stability_parameter(inputs["g0"], theta),
        aspect_ratio=diagnostics.aspect_ratio(x), axis_ratio=diagnostics.axis_ratio(x),
        u_x=float(com_velocity[0]), u_y=float(com_velocity[1]), u_z=float(com_velocity[2]),
        settling_angle_deg=diagnostics.settling_angle_deg(com_velocity),
        tension_max=t_max, tension_min=t_min, s_tension_max=s_max,
        length_error=diagnostics.relative_length_error(x),
    )
    return {key: values[key] for key in SUMMARY_FIELDS}


def evaluate_maps(x, g0, w=DEFAULT_W):
    """Velocity coefficients u (3, 2n+1) and multiplier T (2n+1) of shape x."""
    x = np.ascontiguousarray(x, dtype=float)
    return _velocity_and_multiplier(problems.make_loop_problem((x.shape[-1] - 1) // 2, g0, w), x)


def _velocity_and_multiplier(problem, x):
    x = np.ascontiguousarray(x, dtype=float)
    u = np.empty_like(x)
    physics.loop_velocity(x, problem.g0, problem.w, problem.ops, problem.ws, u)
    return u, problem.ws.tension.copy()


def simulate(
    g0, theta0_deg=None, *, n=None, t_span=(0.0, DEFAULT_T_END), t_eval=None,
    snapshots=2, rtol=DEFAULT_RTOL, atol=DEFAULT_ATOL, w=DEFAULT_W,
    perturbation=None, seed=DEFAULT_SEED, method="rkf45",
    max_steps=DEFAULT_MAX_STEPS, length_tol=DEFAULT_LENGTH_TOL, first_step=None,
    max_step=math.inf, min_step=0.0, steady_tol=None, steady_interval=DEFAULT_STEADY_INTERVAL,
    initial=None, initial_case_id=None,
):
    """Simulate a loop released as a perturbed circle tilted by ``theta0_deg``.

    Parameters follow ``scipy.integrate.solve_ivp`` where they overlap:
    ``t_span`` (t0, t_end), ``t_eval`` (output times; default ``snapshots``
    equally spaced times including both ends), ``rtol``/``atol``, ``method``,
    ``first_step``, ``max_step``, ``min_step``.  ``steady_tol`` (default off)
    stops early at a steady terminal state (``integrate.step_options``).
    ``g0`` is gravity over
    stiffness, ``w`` the length-penalty rate, ``perturbation`` the RMS size of
    the seeded initial perturbation (``initial`` module; default 1e-3, n = 6).

    ``initial`` starts from a given shape instead of the tilted circle:
    coefficients (3, 2m+1) or a path (point file or results, with
    ``initial_case_id``; ``shapes.load_initial``).  n defaults to the shape's
    order (6 for point files; coefficients are resized, exactly when n ≥ m);
    ``theta0_deg`` must then be None and is recorded as the shape's measured
    tilt; ``perturbation`` defaults to 0 (``shapes.perturb`` when > 0).
    ``result.initial_info`` holds the shape's diagnostics (``shapes``).

    Never raises for a failed integration: see ``result.status``.
    """
    g0 = check_real("g0", g0, low=0.0)
    if n is not None:
        n = check_integer("n", n, 1)
    start, initial_info = None, None
    if initial is None:
        if theta0_deg is None:
            raise ValueError("theta0_deg is required unless an initial shape is given")
        theta0_deg = check_real("theta0_deg", theta0_deg, low=0.0, high=90.0)
        n = DEFAULT_N if n is None else n
        perturbation = DEFAULT_PERTURBATION if perturbation is None else perturbation
    else:
        if theta0_deg is not None:
            raise ValueError(f"theta0_deg must be None with an initial shape (its tilt is "
                             f"measured), got {theta0_deg!r}")
        start, initial_info = shapes.resolve_initial(initial, n, initial_case_id)
        n, theta0_deg = initial_info["n"], initial_info["tilt_deg"]
        perturbation = 0.0 if perturbation is None else perturbation
    t0, t_end = (check_real("t_span[0]", t_span[0]), check_real("t_span[1]", t_span[1]))
    if not t_end > t0:
        raise ValueError(f"t_span must be increasing, got {tuple(t_span)!r}")
    rtol = check_real("rtol", rtol, low=0.0, low_open=True)
    atol = check_real("atol", atol, low=0.0)
    w = check_real("w", w, low=0.0)
    perturbation = check_real("perturbation", perturbation, low=0.0)
    seed = check_integer("seed", seed, 0)
    max_steps = check_integer("max_steps", max_steps, 1)
    length_tol = check_real("length_tol", length_tol, low=0.0, low_open=True)
    if method not in _integrate.METHODS:
        raise ValueError(f"method must be one of {sorted(_integrate.METHODS)}, got {method!r}")
    if t_eval is None:
        snapshots = check_integer("snapshots", snapshots, 1)
        t_eval = np.linspace(t0, t_end, snapshots) if snapshots > 1 else np.array([t_end])
    t_eval = np.asarray(t_eval, dtype=float)
    if t_eval.ndim != 1 or not np.all(np.isfinite(t_eval)) or np.any(np.diff(t_eval) <= 0) \
            or (t_eval.size and (t_eval[0] < t0 or t_eval[-1] > t_end)):
        raise ValueError("t_eval must be finite, strictly increasing and within t_span")

    inputs = dict(g0=g0, theta0_deg=theta0_deg, n=n, t_end=t_end, rtol=rtol, atol=atol,
                  w=w, perturbation=perturbation, seed=seed)
    if start is None:
        x0 = _initial_module.initial_shape(n, math.radians(theta0_deg), perturbation, seed)
    else:
        x0 = shapes.perturb(start, perturbation, seed)
    problem = problems.make_loop_problem(n, g0, w)
    y_out = np.full((t_eval.size, x0.size), np.nan)
    if first_step is not None:
        check_real("first_step", first_step, 0.0, low_open=True)
    steady_interval = check_real("steady_interval", steady_interval, 0.0, low_open=True)
    if steady_tol is not None:
        steady_tol = check_real("steady_tol", steady_tol, 0.0, low_open=True)
    options = _integrate.step_options(
        rtol, atol, first_step, min_step, max_step, max_steps, length_tol,
        steady_interval if steady_tol is not None else 0.0, steady_tol or 0.0)
    start = time.perf_counter()
    status, t_final, y_final, n_acc, n_rej, n_rhs, worst_length = _integrate.integrate(
        _integrate.METHODS[method], problem, x0.ravel(), t0, t_end, t_eval, options, y_out,
    )
    wall = time.perf_counter() - start

    reached = t_eval <= t_final
    times = t_eval[reached]
    states = y_out[reached]
    if times.size == 0 or times[-1] < t_final:  # always end on the final state
        times = np.append(times, t_final)
        states = np.vstack([states, y_final[None, :]])
    x = states.reshape(-1, 3, x0.shape[1])
    u = np.empty_like(x)
    multiplier = np.empty((x.shape[0], x0.shape[1]))
    for i in range(x.shape[0]):
        u[i], multiplier[i] = _velocity_and_multiplier(problem, x[i])
    return SimulationResult(
        inputs=inputs, t=times, x=x, u=u, multiplier=multiplier,
        status=_integrate.STATUS_NAMES[status], status_code=int(status),
        t_final=float(t_final), steps_accepted=int(n_acc), steps_rejected=int(n_rej),
        rhs_evals=int(n_rhs), wall_s=wall, length_error_max=float(worst_length),
        initial_info=initial_info,
    )
