"""The result of ``loopsim.simulate``: :class:`SimulationResult`, its summary fields,
and :class:`LoopsimWarning`, the warning of a result that needs care.  No integration
here (``loopsim.api`` runs it)."""
import dataclasses

import numpy as np

from . import diagnostics, integrators, late_motion, outcomes, storage
from .diagnostics import stability_parameter

#: The keys of ``SimulationResult.summary()`` and of ``loopsim run --json``, in order:
#: the inputs, the run's statistics, the outcome and the final state's diagnostics (each
#: a column of ``loopsim.columns.RESULT_COLUMNS``, with its unit).
SUMMARY_FIELDS = storage.SUMMARY_FIELDS
#: solve_ivp's status: -1 the integration failed, 0 it reached t_end, 1 it stopped
#: early at a steady terminal state (a termination event).
FAILED, REACHED_END, STOPPED_EARLY = -1, 0, 1


@dataclasses.dataclass(repr=False)
class SimulationResult:
    """One trajectory of ``simulate``: inputs, states at the requested times, the final
    state, the outcome and the cost.

    Coefficient arrays are real cos/sin coefficients [a0, a1..an, b1..bn] per component
    (``loopsim.spectral``); lengths in L/2π, times in t_u, forces in EI (2π/L)²
    (docs/model.md, "Units").  Returned by ``simulate``, not built by hand.

    Attributes
    ----------
    inputs : dict
        The inputs as run: g0, theta0_deg (degrees), n (the start order), t_end (t_u),
        rtol, atol (L/2π), w (1/t_u), perturbation (L/2π), seed, model, slenderness.
    method : str
        The integrator that ran: "rkf45" or "radau5".
    t : numpy.ndarray
        (k,) the requested times that were reached, in t_u.
    x : numpy.ndarray
        (k, 3, 2 n_used + 1) shape coefficients at ``t``, in L/2π (with ``n="auto"``
        zero-padded to n_used).
    u : numpy.ndarray
        (k, 3, 2 n_used + 1) velocity coefficients at ``t``, in (L/2π)/t_u.
    multiplier : numpy.ndarray
        (k, 2 n_used + 1) coefficients of the tension multiplier T at ``t``, in
        EI (2π/L)²; the axial force is N = T + |x''|² (``tension_profile``).
    t_missed : numpy.ndarray
        The requested times not reached (an early stop or a failure), in t_u.
    t_final : float
        Time reached, in t_u.
    x_final, u_final, multiplier_final : numpy.ndarray
        The final state, as ``x``, ``u``, ``multiplier`` at one time.
    status_code : int
        loopsim's detailed status (``integrators.STATUS_NAMES``).
    steps_accepted, steps_rejected, nfev, njev, nlu : int
        Time steps, right-hand-side and Jacobian evaluations, LU factorisations (all
        orders of ``n="auto"``; the twin's not included).
    wall_s : float
        Wall time of the run in seconds, compilation and the twin left out.
    length_error_max : float
        Largest relative length error (dimensionless) at accepted steps.
    n_used : int
        The truncation order the run ended at.
    tail_max : float
        Largest spectral tail (dimensionless) met at n_used.
    initial_info : dict or None
        Diagnostics of a given initial shape (``loopsim.shapes``), else None.
    aspect_ratio_initial : float
        Aspect ratio of the start (dimensionless).
    twin : dict or None
        The twin's end state and cost (``loopsim.outcomes``), None without a twin.
    motion : dict or None
        Whether the end is a terminal state, and the motion before it
        (``loopsim.late_motion``): terminal_state ("steady", "quiet", "unsteady" or
        "failed"), the late window's tilt (degrees) and aspect-ratio mean, min and max,
        time_since_swing (t_u).
    compile_s : float
        Seconds of kernel compilation during the call.
    thresholds : loopsim.outcomes.Thresholds
        The regime, resolution and determinacy thresholds.
    success : bool
        Whether the integration succeeded (property).
    status : int
        -1 failed, 0 reached t_end, 1 stopped early at a steady state, as solve_ivp's.
    message : str
        The status in words.
    stop_reason : str
        "t_end", "steady" or the failure.
    y : numpy.ndarray
        ``x`` flattened as solve_ivp's (n_state, k).
    end_state : dict
        {regime, theta_final_deg (degrees), aspect_ratio} of the final state.
    regime : str
        "stable", "in-plane", "3d" or "failed".
    resolved : bool
        Whether n_used resolves the run (length error and tail within the thresholds).
    determinacy : dict
        determined, theta_uncertainty_deg (degrees), aspect_uncertainty, twin_nfev.
    determined : bool or None
        Whether the twin agrees (None without a twin).
    terminal_state : str or None
        "steady", "quiet", "unsteady" (no terminal state: still moving) or "failed"
        (``motion``).

    Examples
    --------
    >>> import loopsim
    >>> result = loopsim.simulate(60, 30, twin=False)
    >>> result.regime, result.resolved, result.n_used, result.x_final.shape
    ('in-plane', True, 16, (3, 33))
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
    motion: dict = None  # the late-motion fields (``late_motion``)
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

    @property
    def terminal_state(self):
        """"steady", "quiet", "unsteady" or "failed" (``loopsim.late_motion``); None if not
        measured."""
        return None if self.motion is None else self.motion["terminal_state"]

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
        """Lines a user should read: the run is not resolved, not determined, or ended in
        motion (``terminal_state`` "unsteady")."""
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
        if self.terminal_state == "unsteady":
            m = self.motion
            lines.append(
                f"no terminal state: the loop still moves at t = {self.t_final:g} (tilt "
                f"{m['late_tilt_min_deg']:.3g}-{m['late_tilt_max_deg']:.3g} deg, aspect ratio "
                f"{m['late_aspect_min']:.3g}-{m['late_aspect_max']:.3g} over the last "
                f"{late_motion.LATE_FRACTION:.0%} of the run): its terminal values are a "
                "snapshot of the motion; integrate longer, or read the late-window statistics")
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
            **self.determinacy,
            **(self.motion or {name: None for name in storage.MOTION_FIELDS}))


def terminal_summary(inputs, x, u, multiplier, **run_stats):
    """Summary fields of a final shape x with velocity u and multiplier T.

    ``inputs``: g0, theta0_deg, n, t_end, rtol, atol, w, perturbation, seed, model,
    slenderness;
    ``run_stats``: the ``storage.RUN_FIELDS`` and ``storage.OUTCOME_FIELDS``.
    """
    values = dict(inputs, **run_stats)
    values["q0"] = stability_parameter(inputs["g0"], inputs["theta0_deg"])
    values.update(diagnostics.evaluate(diagnostics.State(x, u, multiplier, inputs["g0"])))
    return {key: values[key] for key in SUMMARY_FIELDS}


class LoopsimWarning(UserWarning):
    """A result that needs care: not resolved at its n, or not determined by its twin.

    ``simulate`` issues one per line of ``SimulationResult.warnings()``; filter them
    with the standard ``warnings`` machinery.

    Examples
    --------
    >>> import warnings
    >>> import loopsim
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("error", loopsim.LoopsimWarning)
    ...     result = loopsim.simulate(150, 60, n=6, twin=False)
    Traceback (most recent call last):
    loopsim.result.LoopsimWarning: not resolved at n = 6 ...
    """
