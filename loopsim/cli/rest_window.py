"""``loopsim rest-window``: the tilts at which a loop can come to rest, from the losses of
stability along the steady branch."""
import json

from .common import HelpFormatter


def add_parser(commands):
    """The ``rest-window`` command and its options."""
    window = commands.add_parser(
        "rest-window", help="the tilts at which loops can come to rest at a given g0",
        description="A settled loop is either a tilted circle (q = g0 sin(theta)/3 below the "
        "in-plane threshold 8.9001) or a steady shape of the in-plane branch, stable up to "
        "the first loss of stability along it. Prints those losses (Hopf with its frequency "
        "Im sigma in 1/t_u, steady, fold) and, per g0, the window of tilts theta_low <= "
        "theta <= theta_high (degrees) of the stable branch: below it loops rest as circles, "
        "above it none can rest (loopsim/stability/rest_window.py, docs/steady-branch.md). "
        "Local model only; about 20 s of one core at n = 16 the first time, then read back "
        "from beside the compiled kernels.",
        formatter_class=HelpFormatter,
    )
    window.add_argument("--g0", required=True, metavar="START:STOP:NUM|v1,v2,...",
                        help="g0 values (gravity over bending stiffness, dimensionless)")
    window.add_argument("--n", type=int, default=16,
                        help="Fourier truncation order of the branch (>= 4; 16 puts the "
                        "out-of-plane loss within 4e-7 of n = 24)")
    window.add_argument("--json", action="store_true", help="print one JSON object")
    return window


def command(args):
    from .. import sweeps, validation
    from ..stability import rest_window

    validation.check_count("--n", args.n, 4, validation.MAX_BRANCH_N,
                           "the continuation's cost grows like n^3 per point")
    g0 = [validation.check_real("--g0", g, 0.0, low_open=True)
          for g in sweeps.parse_values(args.g0, "--g0")]
    window = rest_window.stability_losses(args.n)
    if args.json:
        print(json.dumps(window.as_dict(g0)))
        return 0
    print(f"# steady in-plane branch, n = {window.n}: leaves the circle at q = "
          f"{window.q_circle:.6f}; losses of stability along it:")
    for loss in window.losses:
        what = {"hopf": f"Hopf, Im sigma = {loss.frequency:.4f} 1/t_u",
                "steady": "steady bifurcation", "fold": "fold"}[loss.kind]
        print(f"#   q = {loss.q:.6f}  {what}" + (f" ({loss.sector})" if loss.sector else ""))
    print(f"{'g0':>10} {'theta_low':>10} {'theta_high':>11}  (deg; circles below theta_low)")
    for g in g0:
        low, high = window.tilts(g)
        low_text = "none" if low != low else f"{low:.4f}"   # NaN: no branch at this g0
        print(f"{g:>10.4f} {low_text:>10} {high:>11.4f}")
    return 0
