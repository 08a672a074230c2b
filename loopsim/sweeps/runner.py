"""Running cases: one piece of positions integrated (in the batch kernel, or with
snapshots through ``api.simulate``) into rows of ``storage.RESULT_SCHEMA``."""
import functools
import time
import typing
import warnings

import numpy as np
import pyarrow as pa

from .. import (
    _jitcache, api, columns, diagnostics, integrators, late_motion, models, outcomes, refinement,
    shapes, spectral, storage,
)
from .cases import case_model, case_option
from .chunks import chunk_case_ids
from .directory import write_piece


def _start(case):
    """Keyword arguments of ``shapes.start_shape`` (and ``simulate``) for a case's start."""
    if case.get("initial"):  # a case started from a file (cases column "initial")
        return dict(initial=case["initial"], initial_case_id=case.get("initial_case_id"),
                    n=case["n"], perturbation=case["perturbation"], seed=case["seed"])
    return dict(theta0_deg=case["theta0_deg"], n=case["n"], perturbation=case["perturbation"],
                seed=case["seed"])


def case_method(config, case):
    """The integrator of a case: its own or the sweep's, chosen per case if "auto"."""
    method = case.get("method", config.method)
    if method != "auto":
        return method
    return refinement.auto_method(diagnostics.stability_parameter(case["g0"], case["theta0_deg"]),
                                  case["n"], config.n_auto)


def case_ladder(config, case):
    """The truncation orders a case may use: its n, or with ``n_auto`` the ladder above it
    (up to n_max, or the case model's highest order: ``api.ladder_top``)."""
    n = case["n"]
    top = api.ladder_top(case_model(config, case), config.n_max)
    return refinement.orders(n, max(n, top)) if config.n_auto else (n,)


def _result_row(config, case_id, case, x0, x, status_code, counts, worst, wall_s, t_final,
                method, motion, twin=None):
    """One row of RESULT_SCHEMA for a finished case with final coefficients x (3, 2 n_used + 1);
    worst = (largest length error, largest spectral tail); ``motion``: its late-motion
    fields (``late_motion``); ``twin``: the twin's end state (``api.twin_end_state``) or
    None."""
    n_used = (x.shape[1] - 1) // 2
    ok = status_code in integrators.SUCCESS
    end = outcomes.end_state(case["theta0_deg"], diagnostics.aspect_ratio(x0), x, ok,
                             config.thresholds)
    if not np.all(np.isfinite(x)):
        x = spectral.resize(x0, n_used)  # keep the row finite; the status says why
    model = case_model(config, case)
    problem = models.make_problem(model, n_used, case["g0"], config.w)
    u, multiplier = api.velocity_and_multiplier(problem, x)
    inputs = dict(g0=case["g0"], theta0_deg=case["theta0_deg"], n=case["n"],
                  t_end=case_option(config, case, "t_end"),
                  rtol=case_option(config, case, "rtol"), atol=config.atol, w=config.w,
                  perturbation=case["perturbation"], seed=case["seed"], model=model.name,
                  slenderness=model.slenderness)
    determinacy = (dict(outcomes.NO_TWIN) if twin is None else
                   outcomes.determinacy(end, twin, twin["nfev"], config.thresholds))
    row = api.terminal_summary(
        inputs, x, u, multiplier, method=method, n_used=n_used,
        status=integrators.STATUS_NAMES[status_code], t_final=t_final, wall_s=wall_s,
        tail_max=float(worst[1]), regime=end["regime"],
        resolved=config.thresholds.resolved(worst[0], worst[1]), **determinacy, **motion,
        **dict(zip(integrators.COUNTS, (int(c) for c in counts))))
    row.update(
        case_id=case_id, aspect_ratio_initial=diagnostics.aspect_ratio(x0),
        x_final=x.ravel().tolist(), length_error_max=float(worst[0]),
        stop_reason=integrators.STOP_REASONS[status_code], early_stop=config.early_stop)
    return row


def _traced_case(config, case_id):
    """A case with snapshots: its row and trajectory come from one ``api.simulate`` run,
    so they agree exactly (snapshots come from dense output: the steps, and so the row,
    are those of the batch kernel)."""
    case = config.cases[case_id]
    method = case_method(config, case)
    start = dict(_start(case), **({"n": "auto", "n_start": case["n"]} if config.n_auto else {}))
    model = case_model(config, case)
    with warnings.catch_warnings():  # the row says it, and the sweep's summary counts it
        warnings.simplefilter("ignore", api.LoopsimWarning)
        result = api.simulate(
            case["g0"], **start, t_span=(0.0, case_option(config, case, "t_end")),
            snapshots=config.snapshot_count, rtol=case_option(config, case, "rtol"),
            atol=config.atol, w=config.w,
            method=method, max_steps=config.max_steps, length_tol=config.length_tol,
            steady_tol=config.steady_tol if config.early_stop else None,
            steady_interval=config.steady_interval, n_max=config.n_max,
            tail_tol=config.tail_tol, twin=case_option(config, case, "twin"), model=model.name,
            slenderness=model.slenderness)
    row = _result_row(config, case_id, case, result.x[0], result.x_final, result.status_code,
                      [getattr(result, name) for name in integrators.COUNTS],
                      (result.length_error_max, result.tail_max), result.wall_s,
                      result.t_final, method, result.motion, result.twin)
    table = storage.trajectory_table(result).replace_schema_metadata(None)
    for name in ("x", "multiplier"):  # orders differ between cases: variable-length lists
        table = table.set_column(table.schema.get_field_index(name), name,
                                 table.column(name).cast(pa.list_(pa.float64())))
    table = table.add_column(0, "case_id", pa.array([case_id] * table.num_rows, pa.int64()))
    return row, storage.described(table, columns.TRAJECTORY_COLUMNS)


def _group_order(item):
    """Groups of a chunk in a fixed order (the local model's slenderness None sorts first)."""
    (model, n, method, rtol, twin), _ = item
    return (model.name, model.slenderness or 0.0, n, method, rtol, twin)


class GroupRun(typing.NamedTuple):
    """One group of a chunk's cases run together in the batch kernel (:func:`run_chunk`)."""

    members: list  #: the cases' ids
    x0: list  #: their start shapes (3, 2n + 1)
    sample_times: np.ndarray  #: (B, K) the times of their late-motion samples
    method: str  #: the integrator's name
    run: refinement.CasesRun  #: the runs
    twins: object  #: the twins' ``refinement.CasesRun``, or None without twins


def run_chunk(config, chunk, threads):
    """Integrate one chunk's cases.

    Returns (results Table in RESULT_SCHEMA, snapshots Table or None).  Cases
    without snapshots run in the batch kernel (``refinement.integrate_cases``: a fixed
    n is a ladder of one order; parallel over ``threads`` lanes, serial on one), grouped
    by model, starting n, method, rtol and whether a twin runs; their ``wall_s`` is the
    batch's wall time x threads
    shared in proportion to RHS evaluations (a single case: its own wall time).
    """
    ids = chunk_case_ids(config, chunk)
    traced = sorted(set(ids) & set(config.snapshots_for))
    start = time.perf_counter()
    compiled = _jitcache.compile_seconds()
    groups = [_run_group(config, key, members)
              for key, members in sorted(_groups(config, ids, traced).items(), key=_group_order)]
    wall = time.perf_counter() - start - (_jitcache.compile_seconds() - compiled)
    nfev = integrators.COUNTS.index("nfev")
    total_rhs = sum(int(group.run.counts[:, nfev].sum())
                    + (0 if group.twins is None else int(group.twins.counts[:, nfev].sum()))
                    for group in groups) or 1
    rows = {}
    for group in groups:
        rows.update(_group_rows(config, group, wall * threads, total_rhs))
    snapshots = []
    for case_id in traced:
        rows[case_id], table = _traced_case(config, case_id)
        snapshots.append(table)
    table = pa.Table.from_pylist([rows[i] for i in sorted(rows)], schema=storage.RESULT_SCHEMA)
    return table, (pa.concat_tables(snapshots) if snapshots else None)


def _groups(config, ids, traced):
    """{(model, n, method, rtol, twin): [case ids]} of the cases in ``ids`` not traced."""
    groups = {}
    for case_id in ids:
        if case_id not in traced:
            case = config.cases[case_id]
            key = (case_model(config, case), case["n"], case_method(config, case),
                   case_option(config, case, "rtol"), bool(case_option(config, case, "twin")))
            groups.setdefault(key, []).append(case_id)
    return groups


def _run_group(config, key, members):
    """One group's cases (and their twins) in the batch kernel: a :class:`GroupRun`."""
    model, _, method, rtol, twin = key
    cases = [config.cases[i] for i in members]
    x0 = [shapes.start_shape(**_start(c))[0] for c in cases]
    sample_times = np.array([late_motion.sample_times(0.0, case_option(config, c, "t_end"))
                             for c in cases])
    run = functools.partial(
        refinement.integrate_cases, integrators.METHODS[method],
        [models.case_parameters(model, c["g0"], config.w) for c in cases], x0,
        [case_option(config, c, "t_end") for c in cases],
        ladder=case_ladder(config, cases[0]),
        cost=[diagnostics.stability_parameter(c["g0"], c["theta0_deg"]) for c in cases],
        model=model)
    options = config.step_options()._replace(rtol=float(rtol))
    result = run(options=options, tail_tol=config.tail_tol, sample_times=sample_times)
    twins = None
    if twin:
        twin_rtol, twin_atol, twin_tail = outcomes.twin_tolerances(
            options.rtol, options.atol, config.tail_tol)
        twins = run(options=options._replace(rtol=twin_rtol, atol=twin_atol),
                    tail_tol=twin_tail)
    return GroupRun(members, x0, sample_times, method, result, twins)


def _group_rows(config, group, wall, total_rhs):
    """{case id: row} of a :class:`GroupRun`; each case's ``wall_s`` is its share of
    ``wall`` by RHS evaluations (``total_rhs`` in all)."""
    nfev = integrators.COUNTS.index("nfev")
    run, twins, rows = group.run, group.twins, {}
    for b, case_id in enumerate(group.members):
        case = config.cases[case_id]
        twin = None
        if twins is not None:
            twin = dict(outcomes.end_state(
                case["theta0_deg"], diagnostics.aspect_ratio(group.x0[b]), twins.x_final[b],
                int(twins.status[b]) in integrators.SUCCESS, config.thresholds),
                nfev=int(twins.counts[b, nfev]))
        status = int(run.status[b])
        motion = late_motion.late_motion(
            group.sample_times[b], run.samples[b], 0.0, group.sample_times[b][-1],
            float(run.t_final[b]), run.x_final[b],
            status in integrators.SUCCESS, status == integrators.STEADY, config.thresholds)
        rows[case_id] = _result_row(
            config, case_id, case, group.x0[b], run.x_final[b], status,
            run.counts[b], run.worst[b], wall * run.counts[b, nfev] / total_rhs,
            float(run.t_final[b]), group.method, motion, twin)
    return rows


def run_piece(config, piece, threads=None, out=None, fingerprint=None):
    """One task of a sweep (what a Dask worker runs): :func:`run_chunk` on the positions
    ``piece`` with ``threads`` Numba threads (None: the process's default).  With ``out``
    the worker writes the piece itself and returns only (piece, case_id and status);
    without, it returns (piece, results, snapshots) for the caller to write."""
    import numba

    if threads:
        numba.set_num_threads(min(int(threads), numba.config.NUMBA_NUM_THREADS))
    table, snapshots = run_chunk(config, piece, numba.get_num_threads())
    if out is None:
        return piece, table, snapshots
    write_piece(out, fingerprint, piece, table, snapshots)
    return piece, table.select(["case_id", "status"]), None
