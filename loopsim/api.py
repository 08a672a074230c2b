"""The Python interface: validate, set up, call the compiled driver, summarise.

:func:`simulate` follows ``scipy.integrate.solve_ivp`` where the two overlap:
the arguments ``t_span``, ``t_eval``, ``rtol``, ``atol``, ``method``,
``first_step``, ``max_step``, ``min_step``, and the result's ``t``, ``y``,
``success``, ``status``, ``message``, ``nfev``, ``njev``, ``nlu``.
"""
import math
import time
import warnings

import numpy as np

from . import (
    _jitcache, diagnostics, integrators, late_motion, models, outcomes, refinement, shapes,
    storage, validation,
)
from .defaults import (
    DEFAULT_ATOL, DEFAULT_LENGTH_TOL, DEFAULT_MAX_STEPS, DEFAULT_N_MAX, DEFAULT_RTOL,
    DEFAULT_SEED, DEFAULT_STEADY_INTERVAL, DEFAULT_T_END, DEFAULT_TAIL_TOL, DEFAULT_W,
)
from .diagnostics import stability_parameter
from .result import (  # noqa: F401 - re-exported: loopsim.api is where users met them
    FAILED, REACHED_END, STOPPED_EARLY, SUMMARY_FIELDS, LoopsimWarning, SimulationResult,
    terminal_summary,
)


def ladder_top(model, n_max):
    """The top of a ``model``'s ``n="auto"`` ladder: n_max, or the model's highest order
    (``models.highest_order``) when that is lower."""
    top = models.highest_order(model)
    return n_max if top is None else min(n_max, top)


def twin_end_state(method, g0, w, x0, t0, t_end, options, ladder, tail_tol, theta0_deg,
                   thresholds=outcomes.Thresholds(), model=models.LOCAL):
    """The end state of a run's twin (``outcomes``): the same start and method, every
    tolerance ``outcomes.TWIN_FACTOR`` times stricter.  Returns
    {regime, theta_final_deg, aspect_ratio, nfev, n_used}."""
    rtol, atol, tail_tol = outcomes.twin_tolerances(options.rtol, options.atol, tail_tol)
    run = refinement.integrate_case(
        method, g0, w, x0, t0, t_end, np.empty(0), options._replace(rtol=rtol, atol=atol),
        ladder, tail_tol, model)
    end = outcomes.end_state(theta0_deg, diagnostics.aspect_ratio(x0), run.x_final,
                             run.status in integrators.SUCCESS, thresholds)
    return dict(end, nfev=int(run.counts[integrators.COUNTS.index("nfev")]),
                n_used=int(run.n_used))


def evaluate_maps(x, g0, w=DEFAULT_W, *, model="local", slenderness=None):
    """The velocity and the tension multiplier of a shape: the model's maps at one state.

    Parameters
    ----------
    x : array_like
        (3, 2n + 1) shape coefficients [a0, a1..an, b1..bn] per component, in L/2π.
    g0 : float
        Gravity over bending stiffness, L³ g ρ_L / (8π³ EI) (dimensionless).
    w : float, default 10.0
        Length-penalty rate, in 1/t_u.
    model : {"local", "nonlocal"}, default "local"
        The hydrodynamics (as in ``simulate``).
    slenderness : float or None, default None
        With ``model="nonlocal"``: ε = a/L (dimensionless).

    Returns
    -------
    u : numpy.ndarray
        (3, 2n + 1) velocity coefficients, in (L/2π)/t_u.
    multiplier : numpy.ndarray
        (2n + 1,) coefficients of the tension multiplier T, in EI (2π/L)².

    Raises
    ------
    ValueError
        ``x`` is not (3, 2n + 1) with finite values, or n is beyond the model's highest
        order, or the model or slenderness is bad.

    Examples
    --------
    >>> import numpy as np
    >>> import loopsim
    >>> circle = np.zeros((3, 5))  # n = 2: [a0, a1, a2, b1, b2] per component
    >>> circle[0, 3] = circle[1, 1] = 1.0  # x = sin s, y = cos s: a horizontal circle
    >>> u, multiplier = loopsim.evaluate_maps(circle, 60.0)
    >>> round(float(u[2, 0]), 6)  # it falls at u_z = -g0 (7 - cos 0) / 6 = -g0
    -60.0
    >>> round(float(multiplier[0]), 6)  # T = -1 + q cos s, q = 0 when horizontal
    -1.0
    """
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
    g0, theta0_deg=None, *, n="auto", t_span=(0.0, DEFAULT_T_END), t_eval=None,
    snapshots=2, rtol=DEFAULT_RTOL, atol=DEFAULT_ATOL, w=DEFAULT_W,
    perturbation=None, seed=DEFAULT_SEED, method=None,
    max_steps=DEFAULT_MAX_STEPS, length_tol=DEFAULT_LENGTH_TOL, first_step=None,
    max_step=math.inf, min_step=0.0, steady_tol=None, steady_interval=DEFAULT_STEADY_INTERVAL,
    initial=None, initial_case_id=None, n_max=DEFAULT_N_MAX, tail_tol=DEFAULT_TAIL_TOL,
    n_start=None, twin=True, model="local", slenderness=None,
):
    """Simulate one loop released as a perturbed circle tilted by ``theta0_deg`` (or from a
    given shape), to a resolved terminal state by default.

    The arguments and the result follow ``scipy.integrate.solve_ivp`` where the two
    overlap (``t_span``, ``t_eval``, ``rtol``, ``atol``, ``method``, ``first_step``,
    ``max_step``, ``min_step``; ``t``, ``y``, ``success``, ``status``, ``message``,
    ``nfev``).  Units: lengths in L/2π, times in t_u (docs/model.md, "Units").  The
    default, ``n="auto"``, restarts the run from t0 at the next order whenever its spectral
    tail passes ``tail_tol``; the paper's scheme is ``n=6, method="rkf45"``.

    Parameters
    ----------
    g0 : float
        Gravity over bending stiffness, L³ g ρ_L / (8π³ EI) (dimensionless, >= 0).
    theta0_deg : float or None, default None
        Initial tilt of the loop's plane to the horizontal, in degrees, in [0, 90];
        required unless ``initial`` is given (then None: the tilt is measured).
    n : int or "auto", default "auto"
        Fourier truncation order (1..128), or "auto": start at ``n_start`` and restart
        the run from t0 at the next order of ``defaults.AUTO_ORDERS`` (up to ``n_max``)
        whenever its spectral tail passes ``tail_tol`` (``loopsim.refinement``).
    t_span : (float, float), default (0.0, 10.0)
        Start and end time, in t_u.
    t_eval : array_like or None, default None
        Output times in t_u, strictly increasing within ``t_span`` (returned exactly);
        None: ``snapshots`` equally spaced times including both ends.
    snapshots : int, default 2
        Number of output times when ``t_eval`` is None.
    rtol : float, default 1e-6
        Relative tolerance of the time integration (dimensionless).
    atol : float, default 1e-9
        Absolute tolerance on the shape coefficients, in L/2π.
    w : float, default 10.0
        Length-penalty rate of the inextensibility constraint, in 1/t_u.
    perturbation : float or None, default None
        RMS size of the seeded initial perturbation, in L/2π; None: 1e-3 for the tilted
        circle, 0 for a given shape.
    seed : int, default 0
        Seed of the perturbation.
    method : {"rkf45", "radau5", "auto"} or None, default None
        The integrator; None: "auto" (chosen per case, ``refinement.auto_method``) with
        ``n="auto"`` and "rkf45" (the paper's) at a fixed n.
    max_steps : int, default 2000000
        Most time steps of a run.
    length_tol : float, default 0.25
        Relative length error (dimensionless) at which a run stops as failed.
    first_step, max_step, min_step : float or None, default None, inf, 0.0
        Step-size limits, in t_u (None: chosen by the integrator).
    steady_tol : float or None, default None
        Stop early once the shape and tilt change by less than this (dimensionless) per
        ``steady_interval``; None: integrate to ``t_span[1]``.  Unlike
        ``loopsim.sweep`` (``early_stop=True``), a single run does not stop early by
        default: it is asked for its states at the requested times (``t_eval``,
        ``snapshots``, as ``solve_ivp``), and an early stop would leave the later ones out
        (``t_missed``).  ``steady_tol=loopsim.defaults.DEFAULT_STEADY_TOL`` (1e-6) stops
        exactly as a sweep's case does.
    steady_interval : float, default 0.5
        Interval of the steady-state test (``steady_tol``), in t_u.
    initial : array_like, str or None, default None
        Start from a given shape instead of the tilted circle: coefficients (3, 2m + 1)
        in L/2π, a point file (CSV/Parquet, columns x, y, z; fitted by arc length and
        scaled to length 2π) or results (a ``run --out`` file, a sweep directory).  With
        ``n="auto"`` a point file starts at the lowest order whose truncation of the fit
        leaves out at most ``defaults.INITIAL_CONTENT_TOL`` (1e-12) of its RMS amplitude
        (at least 6, at most the ladder's top), coefficients and results at their own
        order; every order of the ladder starts from that same shape.
    initial_case_id : int or None, default None
        The case of a results ``initial`` holding several.
    n_max : int, default 32
        With ``n="auto"``: the highest order a run may reach (also capped by the model's,
        for nonlocal).
    tail_tol : float, default 1e-5
        With ``n="auto"``: the spectral-tail tolerance (dimensionless) that restarts a run
        at the next order.
    n_start : int or None, default None
        With ``n="auto"``: the first order; None: 6, or a given shape's (see ``initial``).
    twin : bool, default True
        Also run the twin at 10x stricter tolerances that says whether the outcome is
        ``determined`` (``loopsim.outcomes``); run and twin together cost about 2.7 times the
        run alone (docs/auto-and-determinacy.md).
    model : {"local", "nonlocal"}, default "local"
        The hydrodynamics: the paper's local slender-body theory, or full slender-body
        theory (needs ``slenderness``; docs/nonlocal.md), whose n must stay below its
        highest order (``models.highest_order``).
    slenderness : float or None, default None
        With ``model="nonlocal"``: ε = a/L, filament radius over loop length
        (dimensionless, in (0, 0.05]).

    Returns
    -------
    SimulationResult
        The trajectory at the output times, the final state, the outcome (``regime``,
        ``resolved``, ``determined``) and the cost.  A failed integration is a result
        too: see ``result.success``.

    Raises
    ------
    ValueError
        A bad argument (named in the message), ``theta0_deg`` with ``initial`` or neither,
        an unreadable or degenerate initial shape, ``n_start`` without ``n="auto"``, or n
        beyond the model's highest order.

    Warns
    -----
    LoopsimWarning
        The result is not resolved, or not determined (``SimulationResult.warnings``).

    Examples
    --------
    >>> import loopsim
    >>> result = loopsim.simulate(60, 30)  # n="auto": up the ladder, radau5, with its twin
    >>> result.regime, result.resolved, result.determined, result.n_used, result.method
    ('in-plane', True, True, 16, 'radau5')
    >>> paper = loopsim.simulate(20, 30, n=6, method="rkf45")  # the paper's scheme
    >>> paper.regime, paper.resolved, paper.determined
    ('stable', True, True)
    """
    g0 = validation.check_real("g0", g0, low=0.0)
    model = models.choose(model, slenderness)
    refine = isinstance(n, str)
    method = validation.check_choice(
        "method", ("auto" if refine else "rkf45") if method is None else method,
        refinement.METHOD_CHOICES)
    tail_tol = validation.check_real("tail_tol", tail_tol, low=0.0, low_open=True)
    n, n_max = _start_order(n, n_max, n_start, initial, initial_case_id, model, refine)
    x0, theta0_deg, n, perturbation, initial_info = shapes.start_shape(
        theta0_deg, n, perturbation, seed, initial, initial_case_id)
    models.check_order(model, n, "n_start" if refine else "n")
    ladder = refinement.orders(n, max(n, ladder_top(model, n_max))) if refine else (n,)
    if method == "auto":
        method = refinement.auto_method(stability_parameter(g0, theta0_deg), n, refine)
    t0, t_end, t_eval, rtol, atol, w, options = _run_options(
        t_span, t_eval, snapshots, rtol, atol, w, max_steps, length_tol, first_step, min_step,
        max_step, steady_tol, steady_interval)
    inputs = dict(g0=g0, theta0_deg=theta0_deg, n=n, t_end=t_end, rtol=rtol, atol=atol,
                  w=w, perturbation=perturbation, seed=int(seed), model=model.name,
                  slenderness=model.slenderness)
    run, twin_state, motion, wall, compile_s = _run_and_twin(
        integrators.METHODS[method], g0, w, x0, t0, t_end, t_eval, options, ladder,
        tail_tol, theta0_deg, model, twin)
    result = _result(run, inputs, method, t_eval, g0, w, model, x0, initial_info, twin_state,
                     motion, wall, compile_s)
    for line in result.warnings():
        warnings.warn(line, LoopsimWarning, stacklevel=2)
    return result


def _start_order(n, n_max, n_start, initial, initial_case_id, model, refine):
    """:func:`simulate`'s first order (checked) and, with ``n="auto"``, its top order
    ``n_max`` (checked): the start shape's order, or ``n_start``, or the ladder's first."""
    if refine:
        validation.check_choice("n", n, ("auto",))
    if refine:
        n_max = validation.check_order("n_max", n_max)
        if n_start is not None:
            n = n_start
        elif initial is None:
            n = refinement.AUTO_START
        else:  # a point file at the order its content needs; a stored shape at its own
            n = shapes.auto_start_order(initial, initial_case_id, refinement.AUTO_START,
                                        ladder_top(model, n_max))
    elif n is None:
        raise ValueError("n must be an order (1..128) or 'auto', got None")
    elif n_start is not None:
        raise ValueError("n_start applies only with n='auto'")
    if n is not None:
        n = validation.check_order("n_start" if refine else "n", n)
    return n, n_max


def _run_options(t_span, t_eval, snapshots, rtol, atol, w, max_steps, length_tol, first_step,
                 min_step, max_step, steady_tol, steady_interval):
    """:func:`simulate`'s time span, output times and tolerances, checked in this order:
    (t0, t_end, t_eval, rtol, atol, w, the driver's options)."""
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
    t_eval = _output_times(t_eval, snapshots, t0, t_end)
    options = integrators.step_options(
        rtol, atol, first_step, min_step, max_step, max_steps, length_tol,
        steady_interval if steady_tol is not None else 0.0, steady_tol or 0.0)
    return t0, t_end, t_eval, rtol, atol, w, options


def _output_times(t_eval, snapshots, t0, t_end):
    """:func:`simulate`'s output times, checked (an array)."""
    if t_eval is None:
        snapshots = validation.check_integer("snapshots", snapshots, 1)
        t_eval = np.linspace(t0, t_end, snapshots) if snapshots > 1 else np.array([t_end])
    t_eval = np.asarray(t_eval, dtype=float)
    if t_eval.ndim != 1 or not np.all(np.isfinite(t_eval)) or np.any(np.diff(t_eval) <= 0) \
            or (t_eval.size and (t_eval[0] < t0 or t_eval[-1] > t_end)):
        raise ValueError("t_eval must be finite, strictly increasing and within t_span")
    return t_eval


def _run_and_twin(method_object, g0, w, x0, t0, t_end, t_eval, options, ladder, tail_tol,
                  theta0_deg, model, twin):
    """The run (``refinement.CaseRun``, its x_out at ``t_eval``) and, with ``twin``, its
    twin's end state; its late-motion fields (``late_motion``, from samples of the same
    run); the run's own wall time (compilation out, the twin's share out) and the compile
    time."""
    compiled = _jitcache.compile_seconds()
    start = time.perf_counter()
    samples = late_motion.sample_times(t0, t_end)
    times = np.union1d(t_eval, samples)  # one run: dense output leaves the steps alone
    run = refinement.integrate_case(
        method_object, g0, w, x0, t0, t_end, times, options, ladder, tail_tol, model)
    twin_state = None
    if twin and run.status in integrators.SUCCESS:
        twin_state = twin_end_state(method_object, g0, w, x0, t0, t_end, options, ladder,
                                    tail_tol, theta0_deg, model=model)
    elif twin:  # a failed run has no outcome to check: no twin is run, and it is not determined
        twin_state = dict(regime="failed", theta_final_deg=math.nan, aspect_ratio=math.nan,
                          nfev=0, n_used=int(run.n_used))
    compile_s = _jitcache.compile_seconds() - compiled
    wall = time.perf_counter() - start - compile_s
    if twin_state is not None:  # the twin's time is not the run's: split by RHS evaluations
        nfev = int(run.counts[integrators.COUNTS.index("nfev")])
        wall *= float(nfev) / (nfev + twin_state["nfev"])
    motion = late_motion.late_motion(
        samples, run.x_out[np.searchsorted(times, samples)], t0, t_end, run.t_final,
        run.x_final,
        run.status in integrators.SUCCESS, run.status == integrators.STEADY,
        outcomes.Thresholds())
    run = run._replace(x_out=run.x_out[np.searchsorted(times, t_eval)])
    return run, twin_state, motion, wall, compile_s


def _result(run, inputs, method, t_eval, g0, w, model, x0, initial_info, twin_state, motion,
            wall, compile_s):
    """The :class:`SimulationResult` of a run: its states at the output times reached,
    with their velocities and multipliers."""
    problem = models.make_problem(model, run.n_used, g0, w)
    reached = t_eval <= run.t_final
    x = run.x_out[reached]
    u = np.empty_like(x)
    multiplier = np.empty((x.shape[0], run.x_final.shape[1]))
    for i in range(x.shape[0]):
        u[i], multiplier[i] = velocity_and_multiplier(problem, x[i])
    u_final, multiplier_final = velocity_and_multiplier(problem, run.x_final)
    stats = dict(zip(integrators.COUNTS, (int(c) for c in run.counts)))
    return SimulationResult(
        inputs=inputs, method=method, t=t_eval[reached], x=x, u=u, multiplier=multiplier,
        t_missed=t_eval[~reached], t_final=float(run.t_final), x_final=run.x_final,
        u_final=u_final, multiplier_final=multiplier_final, status_code=int(run.status),
        wall_s=wall, length_error_max=float(run.worst[0]), n_used=int(run.n_used),
        tail_max=float(run.worst[1]), initial_info=initial_info,
        aspect_ratio_initial=diagnostics.aspect_ratio(x0), twin=twin_state, motion=motion,
        compile_s=compile_s, **stats)
