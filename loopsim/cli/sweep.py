"""``loopsim sweep``: many loops (a grid or a cases file) into a sweep directory, resumed
when re-run; also reruns of a sweep's failed cases (``--rerun-failed``)."""
import math
import sys

from ..columns import CASE_COLUMNS, CASE_OVERRIDES
from ..defaults import (
    DEFAULT_AUTO_CHUNK_SIZE, DEFAULT_CHUNK_SIZE, DEFAULT_N, PERTURBATION_ENSEMBLE, SEED_TARGETS,
)
from .common import (
    EXIT_FAILED_RUN, HelpFormatter, Parser, add_integration_options, check_auto_options,
    interrupted, real, use_agg,
)


def refinement_advice(config, unresolved):
    """What to rerun unresolved rows with: a larger n, unless their model has none (nonlocal
    SBT's highest order, ``models.highest_order``, already reached)."""
    from .. import models

    tops = [models.highest_order(models.choose(name, eps if name == "nonlocal" else None))
            for name, eps in zip(unresolved["model"], unresolved["slenderness"])]
    capped = sum(top is not None and used >= top for top, used in zip(tops, unresolved["n_used"]))
    if config.n_auto:
        advice = (f"rerun them with a larger --n-max than {config.n_max} (a cases file of their "
                  f"g0, theta0_deg and seed)")
    else:
        advice = "rerun them with a larger --n or --n auto"
    if capped == len(unresolved):
        return ("they are at their model's highest order (nonlocal SBT's short-wave limit, "
                "docs/nonlocal.md): no larger n exists; a smaller --slenderness resolves more")
    if capped:
        return f"{advice}; {capped} of them are at their model's highest order, beyond any n"
    return advice


def add_parser(commands):
    """The ``sweep`` command and its options."""
    sweep = commands.add_parser(
        "sweep", help="run (or resume) an ensemble over (g0, theta0, n, seed) into Parquet",
        description="Integrate many loops in parallel and write one row per case into "
        "chunk files in DIR, a Parquet dataset (pandas.read_parquet(DIR); checked: "
        "loopsim.read_results(DIR)). Re-running the same command resumes (also with another "
        "--chunk-size, after an exit 3 once the disk is fixed, or after a signal: finished "
        "cases are kept). Exit 1: some case failed (its row says why; see --rerun-failed).",
        formatter_class=HelpFormatter,
    )
    _add_case_options(sweep)
    integration = sweep.add_argument_group("integration of each case")
    add_integration_options(integration)
    integration.add_argument("--no-early-stop", action="store_true",
                             help="always integrate to --t-end (default: stop once the shape "
                             "and tilt are steady, see docs/sweeps.md)")
    sharp = sweep.add_argument_group(
        "--seeds auto: seeds added per point until it is deterministic (every seed in one "
        "regime, tilts within 1 deg, aspect ratios within 0.1), sharp (both targets met) or at "
        "--max-seeds")
    for name, (metavar, text) in SEED_TARGET_HELP.items():
        sharp.add_argument("--" + name.replace("_", "-"), type=real if metavar != "K" else int,
                           default=None, metavar=metavar,
                           help=f"{text} (default: {SEED_TARGETS[name][1]})")
    _add_output_options(sweep.add_argument_group("output"))
    _add_backend_options(
        sweep.add_argument_group("where the cases run (default: this machine's threads)"))
    return sweep


def _add_case_options(sweep):
    """The options that say which cases a sweep runs (a grid, or a cases file)."""
    grid = sweep.add_argument_group("cases (a grid, or --cases FILE)")
    grid.add_argument("--g0", metavar="START:STOP:NUM|v1,v2,...",
                      help="g0 values (gravity over bending stiffness, dimensionless)")
    grid.add_argument("--theta0", metavar="START:STOP:NUM|v1,v2,...",
                      help="initial tilts, in degrees")
    grid.add_argument("--n", default="auto", metavar="N[,N...]|auto",
                      help="truncation orders, or auto: every case starts at n = "
                      f"{DEFAULT_N} and is restarted from t = 0 at the next order (up to "
                      "--n-max) whenever its spectral tail passes --tail-tol (the paper's "
                      "scheme: --n 6 --method rkf45)")
    grid.add_argument("--seeds", default="1", metavar="K|auto",
                      help="seeds 0..K-1 per point, or auto: per point 4, 8, 16 ... seeds "
                      "until its answer is sharp (see --p-halfwidth; docs/distributions.md). "
                      "Probabilities over seeds are over this ensemble: "
                      + PERTURBATION_ENSEMBLE)
    grid.add_argument("--cases", metavar="FILE", help="CSV/Parquet with columns "
                      f"{', '.join(CASE_COLUMNS[:2])} [, {', '.join(CASE_COLUMNS[2:])}] "
                      "instead of a grid, one row per case (initial: a point file or results "
                      "per row, paths relative to FILE, theta0_deg then left empty; "
                      f"{', '.join(CASE_OVERRIDES)}: that row's own option)")


def _add_output_options(output):
    """What a sweep writes and shows, and its threads and chunks."""
    output.add_argument("--snapshots-for", metavar="CASE_IDS", default="",
                       help="case ids (v1,v2,...) whose trajectories are stored as snapshots")
    output.add_argument("--snapshots", type=int, default=101, metavar="K",
                       help="states stored of each --snapshots-for trajectory: K equally "
                       "spaced times, both ends included (as run --snapshots)")
    output.add_argument("--threads", type=int, default=None, metavar="K",
                       help="threads (default: all cores)")
    output.add_argument("--chunk-size", type=int, default=None, metavar="K",
                       help="cases per chunk file (and per Dask task; default "
                       f"{DEFAULT_CHUNK_SIZE}, or {DEFAULT_AUTO_CHUNK_SIZE} with --n auto, "
                       "whose cases take seconds to minutes: a SIGKILL loses the unwritten "
                       "chunks); may "
                       "change on resume")
    output.add_argument("--out", metavar="DIR",
                       help="sweep directory, made if absent (required, except with "
                       "--rerun-failed)")
    output.add_argument("--figure", metavar="PNG", help="also draw the phase diagram")
    output.add_argument("--quiet", action="store_true", help="no progress line, only a summary")
    output.add_argument("--progress-every", type=real, default=30.0, metavar="SECONDS",
                       help="progress line interval, in seconds of wall time, when stderr is "
                       "not a terminal (a log file)")


def _add_backend_options(where):
    """Where the cases run: Dask, job-array shards, reruns of failed cases."""
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="send chunks as tasks to the Dask scheduler at ADDRESS "
                       "(tcp://host:8786); finished chunks come back and are written here")
    where.add_argument("--dask", action="store_true",
                       help="start a Dask LocalCluster here and send chunks to it")
    where.add_argument("--workers", type=int, default=None, metavar="K",
                       help="with --dask: worker processes, at most the cores (default: "
                       "cores / --threads)")
    where.add_argument("--shard", metavar="I/N",
                       help="only chunks k with k %% N == I (0 <= I < N), for job arrays: "
                       "N jobs with the same command and I = the array index fill DIR together")
    where.add_argument("--rerun-failed", metavar="DIR",
                       help="rerun only DIR's failed cases with this command's --method, --rtol "
                       "and --atol; rows replaced, earlier rows kept in DIR/_reruns/ "
                       "(resumable: re-run the same command)")


#: --seeds auto's targets (defaults.SEED_TARGETS: field and default): metavar, help.
SEED_TARGET_HELP = {
    "p_halfwidth": ("P", "largest half-width of each regime probability's 95%% Wilson "
                    "interval"),
    "tilt_halfwidth": ("DEG", "largest half-width of the median terminal tilt's 95%% "
                       "bootstrap interval"),
    "min_seeds": ("K", "seeds of the first round"),
    "max_seeds": ("K", "seeds at most per point"),
    "check_seeds": ("K", "seeds of each point whose runs are samples (its seeds end in "
                    "different regimes, or a twin ends elsewhere) rerun at the twins' stricter "
                    "tolerances to check its distribution (outcome_statistics.compare); that "
                    "point's later seeds run without twins; 0: no check, twins throughout"),
}
RERUN_OPTIONS = ("method", "rtol", "atol")  # what --rerun-failed takes from the command line
#: Options that say where and how a rerun runs, not what: they apply with --rerun-failed.
RERUN_BACKEND = ("rerun_failed", "threads", "quiet", "progress_every", "scheduler", "dask",
                 "workers", "figure")


def _parse_shard(text):
    """'I/N' -> (I, N) with 0 <= I < N, or a one-line error."""
    try:
        index, count = (int(part) for part in text.split("/"))
        if not 0 <= index < count:
            raise ValueError
    except ValueError:
        raise ValueError(f"--shard must be I/N with integers 0 <= I < N, got {text!r}") from None
    return index, count


def _sweep_config(args, sweeps):
    from .. import validation

    check_auto_options(args)
    if args.cases:
        if args.g0 or args.theta0:
            raise ValueError("give either --cases or --g0/--theta0, not both")
        orders = [DEFAULT_N] if args.n == "auto" else sweeps.parse_values(args.n, "--n",
                                                                           integer=True)
        top = None
        if args.n == "auto":  # point files start at the order their content needs
            from .. import api, models

            top = api.ladder_top(models.choose(args.model, args.slenderness), args.n_max)
        cases = sweeps.read_cases_file(args.cases, args.perturbation, orders[0], top)
    else:
        if not (args.g0 and args.theta0):
            raise ValueError("a sweep needs --g0 and --theta0 (or --cases FILE)")
        seeds = 1 if args.seeds == "auto" else args.seeds
        axes = (sweeps.parse_values(args.g0, "--g0"),
                sweeps.parse_values(args.theta0, "--theta0"),
                [DEFAULT_N] if args.n == "auto"
                else sweeps.parse_values(args.n, "--n", integer=True))
        count = math.prod(len(axis) for axis in axes) * seeds
        if count > validation.MAX_CASES:
            raise ValueError(f"the grid has {count} cases (--g0 x --theta0 x --n x --seeds), "
                             f"more than a sweep's {validation.MAX_CASES}: split it")
        cases = sweeps.grid_cases(*axes, seeds, args.perturbation)
    return sweeps.SweepConfig(cases=cases, t_end=args.t_end, rtol=args.rtol, atol=args.atol,
                              w=args.w, method=args.method or (
                                  "auto" if args.n == "auto" else "rkf45"),
                              twin=not args.no_twin, model=args.model,
                              slenderness=args.slenderness,
                              chunk_size=(args.chunk_size if args.chunk_size is not None
                                          else DEFAULT_AUTO_CHUNK_SIZE if args.n == "auto"
                                          else DEFAULT_CHUNK_SIZE),
                              early_stop=not args.no_early_stop,
                              snapshots_for=sweeps.parse_values(
                                  args.snapshots_for, "--snapshots-for", integer=True)
                              if args.snapshots_for else [],
                              snapshot_count=args.snapshots, n_auto=args.n == "auto",
                              n_max=args.n_max, tail_tol=args.tail_tol)


def configuration(args):
    """What a sweep command's parsed arguments ask for, checked, with nothing run: (the
    ``sweeps.SweepConfig``, the ``--seeds auto`` targets or None)."""
    from .. import sweeps

    targets = _parse_seeds(args)
    return _sweep_config(args, sweeps), targets


def _parse_seeds(args):
    """``--seeds K|auto`` into an int or "auto", and the --seeds auto targets
    (``seeds_auto_rule.SeedTargets``, or None), each refused where it does not apply."""
    from .. import seeds_auto_rule

    if args.seeds != "auto":
        try:
            args.seeds = int(args.seeds)
        except ValueError:
            raise ValueError(f"--seeds must be a count K >= 1 or auto, got {args.seeds!r}") \
                from None
        if args.seeds < 1:
            raise ValueError(f"--seeds must be >= 1, got {args.seeds}")
    given = {SEED_TARGETS[name][0]: getattr(args, name) for name in SEED_TARGETS
             if getattr(args, name) is not None}
    if args.seeds != "auto":
        if given:
            name = next(k for k in SEED_TARGETS if SEED_TARGETS[k][0] in given)
            raise ValueError(f"--{name.replace('_', '-')} applies only with --seeds auto")
        return None
    for flag, value in (("--cases", args.cases), ("--shard", args.shard),
                        ("--snapshots-for", args.snapshots_for or None),
                        ("--rerun-failed", args.rerun_failed)):
        if value is not None:
            raise ValueError(f"{flag} does not apply with --seeds auto (its rounds are planned "
                             "from the grid's points as the seeds come in)")
    return seeds_auto_rule.SeedTargets(**given).check()


def _check_rerun_options(args):
    """With --rerun-failed the cases and settings come from DIR: refuse the options that
    would be ignored (given with a value other than their default)."""
    parser = Parser(prog="loopsim")  # the sweep command alone: its defaults
    add_parser(parser.add_subparsers(dest="command", required=True, parser_class=Parser))
    defaults = vars(parser.parse_args(["sweep"]))
    ignored = [key for key in defaults if key not in ("command",) + RERUN_OPTIONS + RERUN_BACKEND
               and getattr(args, key) != defaults[key]]
    if ignored:
        raise ValueError(f"--{ignored[0].replace('_', '-')} does not apply with --rerun-failed "
                         f"(the cases and settings come from the sweep; only "
                         f"{', '.join('--' + k for k in RERUN_OPTIONS)} change)")


def _sampled_cells_text(sampled, config, targets, out):
    """What happened to the cells whose runs are samples (rows of the stop table), for the
    closing line: their later seeds without twins and the check's verdicts, or, with
    ``--check-seeds 0`` or ``--no-twin``, what ran instead."""
    if not config.twin:
        return "no twins and no distribution check (--no-twin)"
    if targets.check_seeds == 0:
        return ("their later seeds ran with twins, and their distributions were not checked "
                "(--check-seeds 0)")
    checked = sampled[sampled["check_seeds"] > 0]
    verdicts = ", ".join(f"{k} {v}" for k, v in
                         sorted(checked["check_verdict"].value_counts().items()))
    check = (f"; their distributions checked against up to "
             f"{int(checked['check_seeds'].max())} seeds each at 10x stricter "
             f"tolerances ({out}/check): {verdicts}") if len(checked) else ""
    return f"their later seeds ran without twins{check}"


def command(args):
    from .. import figures, outcome_statistics, sweeps

    backend = _backend_options(args)
    try:
        out, config, frame, stops = _run(args, backend)
    except KeyboardInterrupt as stopped:  # sweeps.SweepInterrupted, or a Ctrl-C before it
        done = (f"{stopped.done} of {stopped.total} cases done and kept in {stopped.out}; "
                if hasattr(stopped, "done") else "")
        return interrupted(getattr(stopped, "signum", 2),
                            f"{done}re-run the same command to resume")
    sweeps.warn_mixed_columns(frame, out)  # a resume across releases says so
    counts = outcome_statistics.outcome_counts(frame)
    _print_outcomes(counts, out, config, frame)
    seeds_auto = args.rerun_failed is None and args.seeds == "auto"
    if seeds_auto:
        _print_seeds_auto(outcome_statistics.stop_counts(stops), stops, out, config,
                          _parse_seeds(args))
    if args.figure:
        use_agg()
        if seeds_auto:
            figures.save_distribution_figure(outcome_statistics.summarize(frame), frame,
                                             args.figure)
        else:
            figures.save(figures.phase_diagram(frame, rest_window=figures.rest_window_for(frame)),
                         args.figure)
        print(f"{'distribution summary' if seeds_auto else 'phase diagram'}: {args.figure}")
    if counts["failed"]:
        print(f"{counts['failed']} of {counts['cases']} cases failed (column 'status'); exit "
              f"status {EXIT_FAILED_RUN}; rerun them with: "
              f"{outcome_statistics.RERUN_COMMAND.format(out=out)} (or another --rtol)",
              file=sys.stderr)
        return EXIT_FAILED_RUN
    return 0


def _backend_options(args):
    """The options of how a sweep runs (threads, Dask, progress), checked: keyword
    arguments of ``sweeps.run_sweep``."""
    import numba

    from .. import validation

    if args.figure is not None:
        validation.check_output_file("--figure", args.figure)
    if args.threads is not None and not 1 <= args.threads <= numba.config.NUMBA_NUM_THREADS:
        raise ValueError(f"--threads must be in 1..{numba.config.NUMBA_NUM_THREADS} (the "
                         f"cores Numba may use), got {args.threads}")
    if args.workers is not None:
        if not args.dask:
            raise ValueError(f"--workers needs --dask, got --workers {args.workers} without it")
        validation.check_count("--workers", args.workers, 1, validation.MAX_WORKERS,
                               "this machine's cores: each worker is a process that compiles "
                               "its own kernels, and more than the cores only compete")
    if args.scheduler is not None and args.dask:
        raise ValueError("give --scheduler ADDRESS or --dask, not both")
    if not args.progress_every > 0:
        raise ValueError(f"--progress-every must be > 0, got {args.progress_every:g}")
    return dict(threads=args.threads, quiet=args.quiet, command_line=sys.argv,
                scheduler=args.scheduler, local_cluster=args.dask, workers=args.workers,
                progress_interval=args.progress_every)


def _run(args, backend):
    """Rerun a sweep's failed cases, or run a sweep (fixed seeds or ``--seeds auto``):
    (directory, SweepConfig, rows, the ``--seeds auto`` stop table or None)."""
    from .. import sweeps, validation

    stops = None
    if args.rerun_failed is not None:
        _check_rerun_options(args)
        out = args.rerun_failed
        settings = {k: getattr(args, k) for k in RERUN_OPTIONS}
        frame, reran = sweeps.rerun_failed(out, **settings, **backend)
        print(f"reran {reran} failed case(s) with " + ", ".join(
            f"{k} {getattr(args, k)}" for k in RERUN_OPTIONS))
        return out, sweeps.SweepConfig(cases=[]), frame, stops
    if args.out is None:
        raise ValueError("a sweep needs --out DIR (or --rerun-failed DIR)")
    out = validation.check_output_directory("--out", args.out)
    targets = _parse_seeds(args)
    config = _sweep_config(args, sweeps)
    if targets is None:
        frame = sweeps.run_sweep(config, out, shard=None if args.shard is None
                                 else _parse_shard(args.shard), **backend)
    else:
        frame, stops = sweeps.run_seeds_auto(
            config, out, targets, command_line=sys.argv,
            run_round=lambda round_config, directory, weights: sweeps.run_sweep(
                round_config, directory, weights=weights, **backend),
            announce=None if args.quiet else lambda line: print(
                line, file=sys.stderr, flush=True))
    return out, config, frame, stops


def _print_outcomes(counts, out, config, frame):
    """The cases by regime, and those not resolved, not determined or still moving."""
    from .. import outcome_statistics

    print(f"{counts['cases']} cases in {out}: "
          + ", ".join(f"{k} {v}" for k, v in counts["regimes"].items()))
    if counts["unresolved"]:
        print(f"{counts['unresolved']} of {counts['cases']} cases NOT resolved at their n "
              f"(transient length error > {config.thresholds.resolved_length_error:g} or "
              f"spectral tail along the run > {config.thresholds.resolved_tail:g}; column "
              f"'resolved'): their terminal tilt and shape are not converged; "
              + refinement_advice(config, frame[~frame["resolved"]])
              + " (regimes among them: " + ", ".join(
                  f"{k} {v}" for k, v in counts["unresolved_regimes"].items()) + ")")
    if counts["undetermined"]:
        print(f"{counts['undetermined']} of {counts['cases']} cases NOT determined (a twin at "
              "10x stricter tolerances ends elsewhere; column 'determined'): their terminal "
              "tilt is a sample of an ill-conditioned transient, not an outcome (regimes "
              "among them: " + ", ".join(
                  f"{k} {v}" for k, v in counts["undetermined_regimes"].items()) + ")")
    if counts["unsteady"] is None:  # rows of an older release: unknown, never 0
        print(f"still moving at their end (column 'terminal_state'): "
              + outcome_statistics.unsteady_text(counts))
    elif counts["unsteady"]:
        print(f"{counts['unsteady']} of {counts['cases']} cases still MOVE at their end "
              "(column 'terminal_state' unsteady): their terminal values are snapshots of "
              "the motion; the late_* columns give its mean and range over the last fifth "
              "of the run (or run them longer with --t-end) (regimes among them: " + ", ".join(
                  f"{k} {v}" for k, v in counts["unsteady_regimes"].items()) + ")")


def _print_seeds_auto(stopped, stops, out, config, targets):
    """Why the points of a ``--seeds auto`` sweep stopped, which were samples, and which
    had no successful seed."""
    from .. import seeds_auto_rule

    print(f"{stopped['points']} points, seeds until sharp: " + ", ".join(
        f"{k} {v}" for k, v in stopped["reasons"].items())
        + f" (seeds per point {stopped['seeds_min']}-{stopped['seeds_max']}; why each "
        f"stopped: {out}/seeds_auto.parquet; per point: loopsim summary {out})")
    sampled = stops[stops["runs"] == "samples"] if "runs" in stops else stops.iloc[:0]
    if len(sampled):
        print(f"{len(sampled)} points' runs are samples (seeds in several regimes, or a "
              "twin ending elsewhere): " + _sampled_cells_text(sampled, config, targets, out))
    failed = stopped["reasons"].get(seeds_auto_rule.FAILED, 0)
    if failed:
        print(f"{failed} points with no successful seed (stop reason failed): no "
              "distribution, no check")
