"""``loopsim branch``: the steady in-plane shapes continued from the circle's
bifurcation, and their stability."""
import json

from .common import HelpFormatter, real


def add_parser(commands):
    """The ``branch`` command and its options."""
    branch = commands.add_parser(
        "branch", help="steady in-plane shapes from the circle's bifurcation, and their stability",
        description="Relative equilibria (shapes that translate without changing) of the "
        "loop in its plane, continued in q = g0 sin(theta0)/3 from the circle's in-plane "
        "threshold, with their aspect ratio and leading in-plane and out-of-plane "
        "eigenvalues (loopsim/stability/branch.py, docs/stability.md).",
        formatter_class=HelpFormatter,
    )
    branch.add_argument("--n", type=int, default=12, help="Fourier truncation order (>= 4)")
    branch.add_argument("--q-max", type=real, default=25.0, metavar="Q",
                        help="continue up to this q = g0 sin(theta0)/3 (dimensionless; > the "
                        "in-plane threshold 8.9001)")
    branch.add_argument("--json", action="store_true", help="print one JSON object")
    return branch


def command(args):
    from ..stability import branch

    from .. import validation

    validation.check_count("--n", args.n, 4, validation.MAX_BRANCH_N,
                           "the continuation's cost grows like n^3 per point")
    if not args.q_max > 9.0:
        raise ValueError(f"--q-max must be > 9 (the branch starts at q = 8.9001), got {args.q_max}")
    out = branch.branch_summary(args.n, args.q_max, q_min=0.0)
    if args.json:
        print(json.dumps(out))
        return 0
    loss = out["q_loss_out_of_plane"]
    print(f"# steady in-plane shapes, n = {out['n']}, w = {out['w']:g}: bifurcation off the circle "
          f"at q = {out['q_bifurcation']:.9f} (circle's in-plane threshold {out['q_circle']:.9f})")
    print(f"# q_loss_out_of_plane = {'none below --q-max' if loss is None else f'{loss:.6f}'}; "
          "side +1: the half leaving towards q > q_c, -1: the other half, 0: the circle")
    print(f"{'side':>4} {'q':>10} {'aspect':>9} {'in-plane':>11} {'out-of-plane':>13}  stable (in, out)")
    for row in out["branch"]:
        print(f"{row['side']:>4} {row['q']:>10.5f} {row['aspect_ratio']:>9.5f} "
              f"{row['leading_in_plane_real']:>11.5f} {row['leading_out_of_plane_real']:>13.5f}  "
              f"{row['stable_in_plane']!s:>5} {row['stable_out_of_plane']!s:>5}")
    return 0
