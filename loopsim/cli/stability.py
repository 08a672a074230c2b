"""``loopsim stability``: critical q of the translating circle from the full
linearisation, or the paper's operator (``--paper``)."""
import json
import math

from ..defaults import DEFAULT_W
from .common import HelpFormatter, add_model_options, real, use_agg


def add_parser(commands):
    """The ``stability`` command and its options."""
    stability = commands.add_parser(
        "stability", help="critical q of the translating circle (full linearisation)",
        description="Critical stability parameter q = g0 sin(theta0)/3 of the translating "
        "circle from the full linearisation of loopsim's own equations: the in-plane and "
        "out-of-plane thresholds at truncation --n (docs/stability.md). --paper prints the "
        "paper's operator instead (its q_c = 14.561 rests on a sign error).",
        formatter_class=HelpFormatter,
    )
    stability.add_argument("--json", action="store_true", help="print one JSON object")
    full = stability.add_argument_group("full linearisation (default)")
    full.add_argument("--n", type=int, default=None,
                      help="truncation order of the full linearisation (>= 3; default: 16)")
    full.add_argument("--theta0", type=real, default=None, metavar="DEG",
                      help="tilt of the circle in (0, 90] degrees (default: 90; the rates depend "
                      "on q only)")
    full.add_argument("--w", type=real, default=None, metavar="W",
                      help=f"length-penalty rate, in 1/t_u (default: {DEFAULT_W:g})")
    full.add_argument("--q-scan", metavar="START:STOP:NUM|v1,v2,...",
                      help="also the largest growth rate (in 1/t_u) of each sector, the "
                      "paper's and the corrected operator at these q (dimensionless)")
    full.add_argument("--g0", type=real, metavar="G0",
                      help="also the spectrum at g0 = G0 (dimensionless) and --theta0: the --top "
                      "largest eigenvalues (growth rates, in 1/t_u) with sector labels")
    full.add_argument("--top", type=int, default=None, metavar="K",
                      help="eigenvalues listed with --g0 (default: 12)")
    full.add_argument("--onset", type=real, nargs=3, metavar=("SIZE", "T", "DETECT"),
                      help="also the q where a mode of size SIZE (in L/2pi) reaches size DETECT "
                      "(in L/2pi) at time T (in t_u), per sector")
    full.add_argument("--figure", metavar="PNG",
                      help="draw growth rates vs q (paper's operator beside the full sectors)")
    add_model_options(full)
    paper_group = stability.add_argument_group("the paper's operator (--paper)")
    paper_group.add_argument("--paper", action="store_true",
                             help="the table of the paper's operator for n = 1..--n-max instead")
    paper_group.add_argument("--n-max", type=int, default=None, metavar="N",
                             help="largest truncation order of the --paper table (default: 60)")
    return stability


FULL_DEFAULTS = dict(n=16, theta0=90.0, w=DEFAULT_W, top=12)
FULL_ONLY = ("n", "theta0", "w", "q_scan", "g0", "top", "onset", "figure", "slenderness")


def _cmd_stability_full(args):
    from .. import figures

    model = _check_full_options(args)
    full = dict(w=args.w, model=model)
    out = _full_results(args, model, full)
    if args.figure:
        use_agg()
        figures.save(figures.growth_rates(args.n, theta0_deg=args.theta0, **full), args.figure,
                     dpi=120)
        out["figure"] = args.figure
    if args.json:
        print(json.dumps(out))
        return 0
    _print_full(args, model, out)
    return 0


def _check_full_options(args):
    """The full linearisation's options checked (the defaults filled in): its model."""
    from .. import models, validation

    if args.figure is not None:
        validation.check_output_file("--figure", args.figure)
    if args.n_max is not None:
        raise ValueError("--n-max applies only to the --paper table")
    for key, value in FULL_DEFAULTS.items():
        if getattr(args, key) is None:
            setattr(args, key, value)
    if not 3 <= args.n <= validation.MAX_N:
        raise ValueError(f"--n must be in 3..{validation.MAX_N} for the full linearisation, "
                         f"got {args.n}")
    if not 0.0 < args.theta0 <= 90.0:
        raise ValueError(f"--theta0 must be in (0, 90], got {args.theta0}")
    if args.w <= 0.0:
        raise ValueError(f"--w must be > 0, got {args.w}")
    model = models.choose(args.model, args.slenderness)
    models.check_order(model, args.n, "--n")
    if model.name == "nonlocal" and args.theta0 != 90.0:
        raise ValueError(f"--theta0 {args.theta0:g}: with --model nonlocal the in-plane and "
                         "out-of-plane sectors decouple only at --theta0 90 (the normal "
                         "gravity couples them through the nonlocal operator; docs/nonlocal.md)")
    return model


def _nan_none(value):
    return None if math.isnan(value) else value


def _full_results(args, model, full):
    """The JSON object of ``loopsim stability`` (full): critical q of each operator, and
    the q scan, the spectrum at --g0 and the onset q when asked for."""
    from .. import sweeps
    from ..stability import full_linear, onset, paper

    out = {
        "operator": "full", "n": args.n, "theta0_deg": args.theta0, "w": args.w,
        "model": model.name, "slenderness": model.slenderness,
        "q_crit_in_plane": _nan_none(full_linear.critical_q(args.n, "in-plane", args.theta0,
                                                            **full)),
        "q_crit_out_of_plane": _nan_none(full_linear.critical_q(args.n, "out-of-plane",
                                                                args.theta0, **full)),
        "q_crit_paper": _nan_none(paper.critical_q(args.n)),
        "q_crit_corrected_operator": _nan_none(paper.critical_q(args.n, corrected=True)),
    }
    if args.q_scan:
        out["q_scan"] = full_linear.paper_comparison(
            sweeps.parse_values(args.q_scan, "--q-scan"), args.n, args.theta0, **full)
    if args.g0 is not None:
        if args.g0 < 0.0:
            raise ValueError(f"--g0 must be >= 0, got {args.g0}")
        spec = full_linear.full_spectrum(args.g0, args.theta0, args.n, **full)
        top = (spec.sector != "neutral").nonzero()[0][:max(1, args.top)]
        out["spectrum"] = {
            "g0": args.g0, "q": spec.q, "neutral_modes": int((spec.sector == "neutral").sum()),
            "growth_rate": {s: spec.growth_rate(s) for s in full_linear.SECTORS},
            "eigenvalues_real": spec.eigenvalues.real[top].tolist(),
            "eigenvalues_imag": spec.eigenvalues.imag[top].tolist(),
            "sector": spec.sector[top].tolist(),
            "out_of_plane_fraction": spec.out_of_plane_fraction[top].tolist(),
        }
    if args.onset:
        eps, t_end, detect = args.onset
        out["onset"] = {"eps": eps, "t_end": t_end, "detect": detect, **{
            f"q_{s.replace('-', '_')}": _nan_none(onset.onset_q(
                eps, t_end, detect, args.n, s, args.theta0, **full))
            for s in full_linear.SECTORS}}
    return out


def _print_full(args, model, out):
    """The full linearisation's results as text."""
    from ..stability import paper

    print(f"# full linearisation about the translating circle, n = {args.n}, "
          f"theta0 = {args.theta0} deg, w = {args.w}, model = {model.name}"
          + (f" (slenderness {model.slenderness:g})" if model.slenderness else ""))
    for key in ("q_crit_in_plane", "q_crit_out_of_plane", "q_crit_paper", "q_crit_corrected_operator"):
        print(f"{key:<26}  {'no crossing' if out[key] is None else f'{out[key]:.11f}'}")
    print(f"# q_crit_paper: {paper.SIGN_NOTE}")
    if "q_scan" in out:
        print(f"{'q':>10}  {'in-plane':>12}  {'out-of-plane':>12}  {'corrected':>12}  {'paper':>12}")
        for row in out["q_scan"]:
            print(f"{row['q']:>10.5g}  {row['in_plane']:>12.6g}  {row['out_of_plane']:>12.6g}  "
                  f"{row['corrected']:>12.6g}  {row['paper']:>12.6g}")
    if "spectrum" in out:
        sp = out["spectrum"]
        print(f"# spectrum at g0 = {sp['g0']}, q = {sp['q']:.6g} (largest, "
              f"{sp['neutral_modes']} neutral modes left out)")
        for re, im, sec in zip(sp["eigenvalues_real"], sp["eigenvalues_imag"], sp["sector"]):
            print(f"{re:>16.9g} {im:>+12.4g}i  {sec}")
    if "onset" in out:
        for key, value in out["onset"].items():
            print(f"onset {key:<16}  {value}")
    if args.figure:
        print(f"figure: {args.figure}")


def command(args):
    from ..stability import paper
    from ..validation import MAX_N

    if not args.paper:
        return _cmd_stability_full(args)
    given = [key for key in FULL_ONLY if getattr(args, key) is not None] + (
        ["model"] if args.model != "local" else [])
    if given:
        raise ValueError(f"--{given[0].replace('_', '-')} applies only to the full linearisation "
                         "(drop --paper)")
    n_max = 60 if args.n_max is None else args.n_max
    if not 1 <= n_max <= MAX_N:  # the table to 128 took 2.5 s; 100 000 never ended
        raise ValueError(f"--n-max must be in 1..{MAX_N}, got {n_max}")
    table = paper.critical_q_table(n_max)
    if args.json:
        print(json.dumps({"operator": "paper", "note": paper.SIGN_NOTE, "critical_q": {
            str(n): (None if math.isnan(q) else q) for n, q in table}}))
    else:
        print("# critical q of the paper's operator L on span{sin ks, k <= n}")
        print(f"# note: {paper.SIGN_NOTE}")
        print(f"{'n':>3}  q_crit")
        for n, q in table:
            print(f"{n:>3}  {'no crossing' if math.isnan(q) else f'{q:.11f}'}")
    return 0
