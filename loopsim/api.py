"""The Python interface: validate, set up, call the compiled driver, summarise.

:func:`simulate` follows ``scipy.integrate.solve_ivp`` where the two overlap:
the arguments ``t_span``, ``t_eval``, ``rtol``, ``atol``, ``method``,
``first_step``, ``max_step``, ``min_step``, and the result's ``t``, ``y``,
``success``, ``status``, ``message``, ``nfev``, ``njev``, ``nlu``.
"""
import dataclasses
import math
import time
import warnings

import numpy as np

from . import _jitcache, diagnostics, integrators, io, models, outcomes, refinement, shapes, \
    validation
from .config import (
    DEFAULT_ATOL, DEFAULT_LENGTH_TOL, DEFAULT_MAX_STEPS, DEFAULT_N_MAX, DEFAULT_RTOL,
    DEFAULT_SEED, DEFAULT_STEADY_INTERVAL, DEFAULT_T_END, DEFAULT_TAIL_TOL, DEFAULT_W,
)
from .diagnostics import stability_parameter

SUMMARY_FIELDS = io.SUMMARY_FIELDS
#: solve_ivp's status: -1 the integration failed, 0 it reached t_end, 1 it stopped
#: early at a steady terminal state (a termination event).
FAILED, REACHED_END, STOPPED_EARLY = -1, 0, 1


@dataclasses.dataclass(repr=False)
class SimulationResult:
    """One trajectory: inputs, states at the requested times, the final state, statistics.

    ``t`` holds exactly the requested times that were reached (``t_missed`` the
    others, after an early stop or a failure); ``x[i]`` (3, 2 n_used + 1) are the
    position coefficients at ``t[i]``, ``u[i]`` the velocity and
    ``multiplier[i]`` (2n+1) the tension multiplier T there (``spectral``
    layout); ``y`` is ``x`` flattened as solve_ivp's (n_state, n_times).  The
    final state, at ``t_final``, is ``x_final``, ``u_final``,
    ``multiplier_final``.  ``tension_profile(i)`` gives the physical axial
    force N(s).  ``n_used`` is the truncation the run ended at (with ``n="auto"``
    earlier states are zero-padded to it), ``tail_max`` the largest spectral tail met
    at n_used.
    """

    inputs: dict
    method: str
    t: np.ndarray
    x: np.ndarray
    u: np.ndarray
    multiplier: np.ndarray
    t_missed: np.ndarray
    t_final: float
    x_final: np.ndarray
    u_final: np.ndarray
    multiplier_final: np.ndarray
    status_code: int  # loopsim's detailed status (``integrators.STATUS_NAMES``)
    steps_accepted: int
    steps_rejected: int
    nfev: int
    njev: int
    nlu: int
    wall_s: float
    length_error_max: float  # largest |relative length error| at accepted steps
    n_used: int = None
    tail_max: float = float("nan")
    initial_info: dict = None  # diagnostics of a given initial shape (``shapes``), else None
    aspect_ratio_initial: float = float("nan")
    twin: dict = None  # the twin's end state and cost (``outcomes``), or None without one
    compile_s: float = 0.0  # kernel compilation during the call, not counted in wall_s
    thresholds: outcomes.Thresholds = outcomes.Thresholds()

    @property
    def success(self):
        return self.status_code in integrators.SUCCESS

    @property
    def status(self):
        """-1 failed, 0 reached t_end, 1 stopped early at a steady state (as solve_ivp)."""
        if not self.success:
            return FAILED
        return STOPPED_EARLY if self.status_code == integrators.STEADY else REACHED_END

    @property
    def message(self):
        return {REACHED_END: "reached t_end", STOPPED_EARLY: "stopped early: steady state"}.get(
            self.status, integrators.STATUS_NAMES[self.status_code])

    @property
    def stop_reason(self):
        """'t_end', 'steady' (early stop at the terminal state) or the failure."""
        return integrators.STOP_REASONS[self.status_code]

    @property
    def y(self):
        return self.x.reshape(self.x.shape[0], -1).T

    @property
    def end_state(self):
        """{regime, theta_final_deg, aspect_ratio} of the final state."""
        return outcomes.end_state(self.inputs["theta0_deg"], self.aspect_ratio_initial,
                                  self.x_final, self.success, self.thresholds)

    @property
    def regime(self):
        return self.end_state["regime"]

    @property
    def resolved(self):
        """Whether n_used resolves the run (``outcomes.Thresholds.resolved``)."""
        return self.thresholds.resolved(self.length_error_max, self.tail_max)

    @property
    def determinacy(self):
        """``outcomes.DETERMINACY_FIELDS``: determined (None without a twin), the run–twin
        differences of terminal tilt and aspect ratio, the twin's RHS evaluations."""
        if self.twin is None:
            return dict(outcomes.NO_TWIN)
        return outcomes.determinacy(self.end_state, self.twin, self.twin["nfev"],
                                    self.thresholds)

    @property
    def determined(self):
        return self.determinacy["determined"]

    def __repr__(self):
        d = self.determinacy
        return (f"SimulationResult(g0={self.inputs['g0']:g}, theta0_deg="
                f"{self.inputs['theta0_deg']:g}, n_used={self.n_used}, method={self.method!r}, "
                f"message={self.message!r}, regime={self.regime!r}, resolved={self.resolved}, "
                f"determined={d['determined']}, theta_final_deg="
                f"{self.end_state['theta_final_deg']:.4g}, theta_uncertainty_deg="
                f"{d['theta_uncertainty_deg']:.2g}, t_final={self.t_final:g}, "
                f"times={len(self.t)}, nfev={self.nfev}, wall_s={self.wall_s:.3g})")

    def warnings(self):
        """Lines a user should read: the run is not resolved, or not determined."""
        lines = []
        if not self.resolved:
            lines.append(
                f"not resolved at n = {self.n_used} (length error up to "
                f"{self.length_error_max:.2g}, limit {self.thresholds.resolved_length_error:g};"
                f" spectral tail up to {self.tail_max:.2g}, limit "
                f"{self.thresholds.resolved_tail:g}): the terminal tilt and shape are not "
                "converged; increase n or use n auto")
        if self.determined is False and self.success:  # a failure says so in its status
            d = self.determinacy
            lines.append(
                f"outcome not determined: a twin run at {outcomes.TWIN_FACTOR:g}x stricter "
                f"tolerances ends {d['theta_uncertainty_deg']:.2g} deg and "
                f"{d['aspect_uncertainty']:.2g} in aspect ratio away (regime "
                f"{self.twin['regime']!r}): the terminal tilt is a sample of an "
                "ill-conditioned transient, not an outcome")
        return lines

    def tension_profile(self, i=None):
        """(s, N(s)) at requested time i, or at the final state (default)."""
        if i is None:
            return diagnostics.tension_profile(self.x_final, self.multiplier_final)
        return diagnostics.tension_profile(self.x[i], self.multiplier[i])

    def summary(self):
        """Dict with exactly the keys of ``SUMMARY_FIELDS`` (the final state's diagnostics
        and what they mean)."""
        return terminal_summary(
            self.inputs, self.x_final, self.u_final, self.multiplier_final,
            method=self.method, n_used=self.n_used,
            status=integrators.STATUS_NAMES[self.status_code], t_final=self.t_final,
            steps_accepted=self.steps_accepted, steps_rejected=self.steps_rejected,
            nfev=self.nfev, njev=self.njev, nlu=self.nlu, wall_s=self.wall_s,
            tail_max=self.tail_max, regime=self.regime, resolved=self.resolved,
            **self.determinacy)


def ladder_top(model, n_max):
    """The top of a ``model``'s ``n="auto"`` ladder: n_max, or the model's highest order
    (``models.highest_order``) when that is lower."""
    top = models.highest_order(model)
    return n_max if top is None else min(n_max, top)


def terminal_summary(inputs, x, u, multiplier, **run_stats):
    """Summary fields of a final shape x with velocity u and multiplier T.

    ``inputs``: g0, theta0_deg, n, t_end, rtol, atol, w, perturbation, seed, model,
    slenderness;
    ``run_stats``: the ``io.RUN_FIELDS`` and ``io.OUTCOME_FIELDS``.
    """
    values = dict(inputs, **run_stats)
    values["q0"] = stability_parameter(inputs["g0"], inputs["theta0_deg"])
    values.update(diagnostics.evaluate(diagnostics.State(x, u, multiplier, inputs["g0"])))
    return {key: values[key] for key in SUMMARY_FIELDS}


def twin_end_state(method, g0, w, x0, t0, t_end, options, ladder, tail_tol, theta0_deg,
                   thresholds=outcomes.Thresholds(), model=models.LOCAL):
    """The end state of a run's twin (``outcomes``): the same start and method, every
    tolerance ``outcomes.TWIN_FACTOR`` times stricter.  Returns
    {regime, theta_final_deg, aspect_ratio, nfev, n_used}."""
    rtol, atol, tail_tol = outcomes.twin_tolerances(options.rtol, options.atol, tail_tol)
    status, _, x, n_used, counts, _, _ = refinement.integrate_case(
        method, g0, w, x0, t0, t_end, np.empty(0), options._replace(rtol=rtol, atol=atol),
        ladder, tail_tol, model)
    end = outcomes.end_state(theta0_deg, diagnostics.aspect_ratio(x0), x,
                             status in integrators.SUCCESS, thresholds)
    return dict(end, nfev=int(counts[2]), n_used=int(n_used))


def evaluate_maps(x, g0, w=DEFAULT_W, *, model="local", slenderness=None):
    """Velocity coefficients u (3, 2n+1) and multiplier T (2n+1) of shape x under ``model``
    (``simulate``'s ``model`` and ``slenderness``)."""
    x = np.ascontiguousarray(x, dtype=float)
    n = shapes.check_coefficients(x, "x")
    model = models.choose(model, slenderness)
    return velocity_and_multiplier(models.make_problem(model, models.check_order(model, n), g0, w),
                                   x)


def velocity_and_multiplier(problem, x):
    """(u, T) of the loop problem at shape x (3, 2n+1)."""
    x = np.ascontiguousarray(x, dtype=float)
    u = np.empty_like(x)
    multiplier = np.empty(x.shape[1])
    models.evaluate(problem, x.ravel(), u.reshape(-1), multiplier)
    return u, multiplier


def simulate(
    g0, theta0_deg=None, *, n=None, t_span=(0.0, DEFAULT_T_END), t_eval=None,
    snapshots=2, rtol=DEFAULT_RTOL, atol=DEFAULT_ATOL, w=DEFAULT_W,
    perturbation=None, seed=DEFAULT_SEED, method=None,
    max_steps=DEFAULT_MAX_STEPS, length_tol=DEFAULT_LENGTH_TOL, first_step=None,
    max_step=math.inf, min_step=0.0, steady_tol=None, steady_interval=DEFAULT_STEADY_INTERVAL,
    initial=None, initial_case_id=None, n_max=DEFAULT_N_MAX, tail_tol=DEFAULT_TAIL_TOL,
    n_start=None, twin=True, model="local", slenderness=None,
):
    """Simulate a loop released as a perturbed circle tilted by ``theta0_deg``.

    Parameters follow ``scipy.integrate.solve_ivp`` where they overlap:
    ``t_span`` (t0, t_end), ``t_eval`` (the output times, returned exactly;
    default ``snapshots`` equally spaced times including both ends),
    ``rtol``/``atol``, ``method`` (``integrators.METHODS`` or "auto"; default
    "rkf45", the paper's scheme, at a fixed n and "auto" with ``n="auto"``), ``first_step``,
    ``max_step``, ``min_step``.  ``steady_tol`` (default off) stops early at a
    steady terminal state (``integrators.step_options``).  ``g0`` is gravity
    over stiffness, ``w`` the length-penalty rate, ``perturbation`` the RMS
    size of the seeded initial perturbation (``shapes.circle``; default 1e-3,
    n = 6).  ``n="auto"`` starts at ``n_start`` (default 6, or a given shape's
    order) and raises n up to ``n_max`` whenever the spectral tail
    passes ``tail_tol`` (``loopsim.refinement``).  ``method="auto"`` picks the integrator for the case
    (``refinement.auto_method``).  ``twin`` (default on) also runs the stricter twin
    that says whether the outcome is determined (``loopsim.outcomes``; about doubles
    the cost); ``result.warnings()`` lists what a user should know (also issued as
    Python warnings).  ``model`` "local" (the paper's local slender-body theory, the
    default) or "nonlocal" (full slender-body theory, docs/nonlocal.md) with
    ``slenderness`` ε = a/L (filament radius over loop length); the nonlocal model's n must stay
    below the first mode its operator is not positive at (``models.highest_order``; with
    ``n="auto"`` the ladder stops there, whatever ``n_max``).

    ``initial`` starts from a given shape instead of the tilted circle:
    coefficients (3, 2m+1) or a path (point file or results, with
    ``initial_case_id``); see ``shapes.start_shape`` for the defaults.
    ``result.initial_info`` holds the shape's diagnostics.

    Never raises for a failed integration: see ``result.success``.
    """
    g0 = validation.check_real("g0", g0, low=0.0)
    model = models.choose(model, slenderness)
    refine = isinstance(n, str)
    method = validation.check_choice(
        "method", ("auto" if refine else "rkf45") if method is None else method,
        refinement.METHOD_CHOICES)
    tail_tol = validation.check_real("tail_tol", tail_tol, low=0.0, low_open=True)
    if refine:
        validation.check_choice("n", n, ("auto",))
    if refine:
        n = n_start if n_start is not None else (
            refinement.AUTO_START if initial is None else None)
        n_max = validation.check_order("n_max", n_max)
    elif n_start is not None:
        raise ValueError("n_start applies only with n='auto'")
    if n is not None:
        n = validation.check_order("n_start" if refine else "n", n)
    x0, theta0_deg, n, perturbation, initial_info = shapes.start_shape(
        theta0_deg, n, perturbation, seed, initial, initial_case_id)
    models.check_order(model, n, "n_start" if refine else "n")
    ladder = refinement.orders(n, max(n, ladder_top(model, n_max))) if refine else (n,)
    if method == "auto":
        method = refinement.auto_method(stability_parameter(g0, theta0_deg), n, refine)
    method_object = integrators.METHODS[method]
    t0, t_end = (validation.check_real("t_span[0]", t_span[0]),
                 validation.check_real("t_span[1]", t_span[1]))
    if not t_end > t0:
        raise ValueError(f"t_span must be increasing, got {tuple(t_span)!r}")
    rtol = validation.check_real("rtol", rtol, low=0.0, low_open=True)
    atol = validation.check_real("atol", atol, low=0.0)
    w = validation.check_real("w", w, low=0.0)
    max_steps = validation.check_integer("max_steps", max_steps, 1)
    length_tol = validation.check_real("length_tol", length_tol, low=0.0, low_open=True)
    if first_step is not None:
        validation.check_real("first_step", first_step, 0.0, low_open=True)
    steady_interval = validation.check_real("steady_interval", steady_interval, 0.0,
                                            low_open=True)
    if steady_tol is not None:
        steady_tol = validation.check_real("steady_tol", steady_tol, 0.0, low_open=True)
    if t_eval is None:
        snapshots = validation.check_integer("snapshots", snapshots, 1)
        t_eval = np.linspace(t0, t_end, snapshots) if snapshots > 1 else np.array([t_end])
    t_eval = np.asarray(t_eval, dtype=float)
    if t_eval.ndim != 1 or not np.all(np.isfinite(t_eval)) or np.any(np.diff(t_eval) <= 0) \
            or (t_eval.size and (t_eval[0] < t0 or t_eval[-1] > t_end)):
        raise ValueError("t_eval must be finite, strictly increasing and within t_span")

    inputs = dict(g0=g0, theta0_deg=theta0_deg, n=n, t_end=t_end, rtol=rtol, atol=atol,
                  w=w, perturbation=perturbation, seed=int(seed), model=model.name,
                  slenderness=model.slenderness)
    options = integrators.step_options(
        rtol, atol, first_step, min_step, max_step, max_steps, length_tol,
        steady_interval if steady_tol is not None else 0.0, steady_tol or 0.0)
    compiled = _jitcache.compile_seconds()
    start = time.perf_counter()
    status, t_final, x_final, n_used, counts, worst, x_out = refinement.integrate_case(
        method_object, g0, w, x0, t0, t_end, t_eval, options, ladder, tail_tol, model)
    twin_state = None
    if twin and status in integrators.SUCCESS:
        twin_state = twin_end_state(method_object, g0, w, x0, t0, t_end, options, ladder,
                                    tail_tol, theta0_deg, model=model)
    elif twin:  # a failed run has no outcome to check: no twin is run, and it is not determined
        twin_state = dict(regime="failed", theta_final_deg=math.nan, aspect_ratio=math.nan,
                          nfev=0, n_used=int(n_used))
    compile_s = _jitcache.compile_seconds() - compiled
    wall = time.perf_counter() - start - compile_s
    if twin_state is not None:  # the twin's time is not the run's: split by RHS evaluations
        wall *= float(counts[2]) / (counts[2] + twin_state["nfev"])

    problem = models.make_problem(model, n_used, g0, w)
    reached = t_eval <= t_final
    x = x_out[reached]
    u = np.empty_like(x)
    multiplier = np.empty((x.shape[0], x_final.shape[1]))
    for i in range(x.shape[0]):
        u[i], multiplier[i] = velocity_and_multiplier(problem, x[i])
    u_final, multiplier_final = velocity_and_multiplier(problem, x_final)
    stats = dict(zip(integrators.COUNTS, (int(c) for c in counts)))
    result = SimulationResult(
        inputs=inputs, method=method, t=t_eval[reached], x=x, u=u, multiplier=multiplier,
        t_missed=t_eval[~reached], t_final=float(t_final), x_final=x_final, u_final=u_final,
        multiplier_final=multiplier_final, status_code=int(status), wall_s=wall,
        length_error_max=float(worst[0]), n_used=int(n_used), tail_max=float(worst[1]),
        initial_info=initial_info, aspect_ratio_initial=diagnostics.aspect_ratio(x0),
        twin=twin_state, compile_s=compile_s, **stats)
    for line in result.warnings():
        warnings.warn(line, LoopsimWarning, stacklevel=2)
    return result


class LoopsimWarning(UserWarning):
    """A result that needs care: not resolved, or not determined
    (``SimulationResult.warnings``)."""
