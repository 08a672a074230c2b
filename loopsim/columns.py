"""Every column loopsim writes, declared once: its unit and what it means.

The units are those of the dimensionless equations (``loopsim.config``): lengths in
L/2π (the loop has length 2π), time in the paper's time unit t_u (§3), forces in
EI (2π/L)², angles in degrees at the interface.  The declarations go into each Parquet
field's metadata (keys ``unit`` and ``description``), into ``_sweep.json`` and a
results frame's ``attrs["loopsim"]["columns"]``, and into the docs' column table
(``python -m loopsim.columns`` prints it as Markdown).
"""
LENGTH = "L/2pi"
TIME = "t_u"
VELOCITY = "(L/2pi)/t_u"
FORCE = "EI (2pi/L)^2"
ONE = "1"  # a pure number
DEG = "deg"
COUNT = "count"
TEXT = "text"
FLAG = "bool"

#: name: (unit, description) of every column of a sweep's result files, in file order.
RESULT_COLUMNS = {
    "case_id": (COUNT, "the case's index in the sweep's case list (_sweep.json)"),
    "g0": (ONE, "gravity over bending stiffness, L^3 g rho_L / (8 pi^3 EI)"),
    "theta0_deg": (DEG, "initial tilt of the loop's plane to the horizontal (measured from "
                        "the shape for an --initial start)"),
    "n": (COUNT, "the truncation order the case started at (with --n auto: the ladder's "
                 "first)"),
    "q0": (ONE, "stability parameter of the start, g0 sin(theta0) / 3"),
    "t_end": (TIME, "requested final time"),
    "rtol": (ONE, "relative tolerance of the time integration"),
    "atol": (LENGTH, "absolute tolerance of the time integration (on coefficients)"),
    "w": ("1/t_u", "length-penalty rate of the inextensibility constraint"),
    "perturbation": (LENGTH, "RMS size of the seeded initial perturbation"),
    "seed": (COUNT, "seed of the initial perturbation"),
    "model": (TEXT, "the hydrodynamic model: local (the paper's local slender-body theory) "
                    "or nonlocal (full slender-body theory, docs/nonlocal.md)"),
    "slenderness": (ONE, "filament radius over loop length, a/L, of the nonlocal model "
                         "(null for the local one)"),
    "method": (TEXT, "the integrator that ran the case: rkf45 or radau5 (--method auto "
                     "chooses per case)"),
    "n_used": (COUNT, "the truncation order the case ended at (with --n auto: the order "
                      "whose run from the start stayed within --tail-tol)"),
    "status": (TEXT, "ok, or why the integration failed"),
    "t_final": (TIME, "time reached (t_end, or earlier at a steady state or a failure)"),
    "steps_accepted": (COUNT, "accepted time steps"),
    "steps_rejected": (COUNT, "rejected time steps"),
    "nfev": (COUNT, "right-hand-side evaluations of the steps (all orders of --n auto)"),
    "njev": (COUNT, "Jacobian evaluations (radau5)"),
    "nlu": (COUNT, "LU factorisations (radau5)"),
    "wall_s": ("s", "wall time of the case, compilation and the twin left out (a batch's "
                    "wall time x threads shared in proportion to nfev)"),
    "tail_max": (ONE, "largest spectral tail (the top two modes' share of the deformation) "
                      "along the run at n_used, once the top modes grew"),
    "theta_final_deg": (DEG, "terminal tilt of the best-fit plane to the horizontal"),
    "q_final": (ONE, "g0 sin(theta_final) / 3"),
    "aspect_ratio": (ONE, "largest / middle eigenvalue of the centreline's covariance (a "
                          "ratio of variances, as in the paper)"),
    "axis_ratio": (ONE, "sqrt(aspect_ratio): the ratio of the principal axes"),
    "u_x": (VELOCITY, "centre-of-mass velocity, x"),
    "u_y": (VELOCITY, "centre-of-mass velocity, y"),
    "u_z": (VELOCITY, "centre-of-mass velocity, z (gravity along -z: negative, falling)"),
    "settling_angle_deg": (DEG, "angle between the centre-of-mass velocity and gravity"),
    "tension_max": (FORCE, "largest axial force N = T + |x''|^2 (positive: stretched)"),
    "tension_min": (FORCE, "smallest axial force N"),
    "s_tension_max": (LENGTH, "arc length where N is largest"),
    "length_error": (ONE, "terminal relative length error (L - 2 pi) / 2 pi"),
    "spectral_tail": (ONE, "the terminal shape's top two modes' share of its deformation"),
    "regime": (TEXT, "stable | in-plane | 3d | failed (thresholds in _sweep.json)"),
    "resolved": (FLAG, "length_error_max and tail_max within the thresholds: n_used "
                       "resolves the case (False: its outcome is not converged in n)"),
    "determined": (FLAG, "a twin from the same start at 10x stricter tolerances ends in the "
                         "same regime within the determined_* thresholds (False: the terminal "
                         "tilt is a sample of an ill-conditioned transient, or the run "
                         "failed; null: no twin was asked for)"),
    "theta_uncertainty_deg": (DEG, "|theta_final_deg - the twin's|: the terminal tilt's "
                                   "error estimate at the tolerances used"),
    "aspect_uncertainty": (ONE, "|aspect_ratio - the twin's|"),
    "twin_nfev": (COUNT, "right-hand-side evaluations of the twin (0: none ran)"),
    "twin_regime": (TEXT, "the twin's regime (null: no twin ran)"),
    "twin_theta_final_deg": (DEG, "the twin's terminal tilt (NaN: no twin ran)"),
    "twin_aspect_ratio": (ONE, "the twin's terminal aspect ratio (NaN: no twin ran)"),
    "stop_reason": (TEXT, "t_end | steady (terminal state reached early) | the failure"),
    "aspect_ratio_initial": (ONE, "aspect ratio of the start"),
    "length_error_max": (ONE, "largest |relative length error| along the trajectory"),
    "x_final": (LENGTH, "terminal shape coefficients, row-major (3, 2 n_used + 1): "
                        "loopsim.coefficients(row) reshapes them"),
}

#: name: (unit, description) of the columns of a trajectory (``run --out``, snapshots).
TRAJECTORY_COLUMNS = {
    "case_id": RESULT_COLUMNS["case_id"],
    "t": (TIME, "time of the snapshot"),
    "theta_deg": (DEG, "tilt of the best-fit plane to the horizontal"),
    "aspect_ratio": RESULT_COLUMNS["aspect_ratio"],
    "tension_max": RESULT_COLUMNS["tension_max"],
    "tension_min": RESULT_COLUMNS["tension_min"],
    "length_error": (ONE, "relative length error (L - 2 pi) / 2 pi"),
    "spectral_tail": (ONE, "the top two modes' share of the deformation"),
    "x": (LENGTH, "shape coefficients, row-major (3, 2n + 1)"),
    "multiplier": (FORCE, "coefficients (2n + 1) of the tension multiplier T; the axial "
                          "force is N = T + |x''|^2"),
}


def field_metadata(name, table=RESULT_COLUMNS):
    """Parquet field metadata of a column: {b"unit": ..., b"description": ...}."""
    unit, description = table[name]
    return {b"unit": unit.encode(), b"description": description.encode()}


def markdown(table=RESULT_COLUMNS):
    """The column table as Markdown (docs), a ``|`` inside a unit or a description
    escaped as ``\\|`` so that it does not end its cell."""
    def cell(text):
        return text.replace("|", "\\|")
    lines = ["| column | unit | meaning |", "|---|---|---|"]
    lines += [f"| `{name}` | {cell(unit)} | {cell(text)} |" for name, (unit, text) in table.items()]
    return "\n".join(lines)


if __name__ == "__main__":
    print(markdown())
