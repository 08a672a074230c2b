"""Where loops can rest (loopsim.stability.rest_window): the losses of stability along the
steady branch and the tilt windows they give, against the independent computation of
../shared/physics-notes.md ("Where 3D loops come to rest", 2026-12-06/07): out of plane a
Hopf point at q = 37.553191 (Im sigma = 22.088), in plane a Hopf point at q = 45.443265
(Im sigma = 66.569), the fold near q = 46.38; windows 6.71-29.53 deg at g0 = 228.6 and
4.4-18.8 deg at g0 = 350."""
import json
import math
import os
import subprocess
import sys

import pytest

from loopsim.stability import rest_window as rw


@pytest.fixture(scope="module")
def window():
    return rw.stability_losses(rw.DEFAULT_WINDOW_N, cache=False)  # computed here, not read


def test_losses_along_the_branch(window):
    out, inp, fold = window.losses
    assert (out.kind, out.sector) == ("hopf", "out-of-plane")
    assert out.q == pytest.approx(37.553191, abs=1e-5)
    assert out.frequency == pytest.approx(22.088, abs=1e-3)
    assert (inp.kind, inp.sector) == ("hopf", "in-plane")
    assert inp.q == pytest.approx(45.443265, abs=1e-5)
    assert inp.frequency == pytest.approx(66.569, abs=1e-3)
    assert fold.kind == "fold" and fold.q == pytest.approx(46.38, abs=0.01)
    assert window.q_circle == pytest.approx(8.9000904456, abs=1e-8)
    assert window.q_loss == out.q


@pytest.mark.parametrize("g0, low, high, digits", [(228.57142857142856, 6.71, 29.53, 2),
                                                   (350.0, 4.4, 18.8, 1)])
def test_tilt_windows(window, g0, low, high, digits):
    lo, hi = window.tilts(g0)
    assert round(lo, digits) == low and round(hi, digits) == high
    # the edges are the q's: g0 sin(theta) / 3
    assert g0 * math.sin(math.radians(lo)) / 3 == pytest.approx(window.q_circle)
    assert g0 * math.sin(math.radians(hi)) / 3 == pytest.approx(window.q_loss)


def test_window_edges_at_small_and_moderate_g0():
    # below 3 q_c no tilt reaches the branch; below 3 q_loss every tilt above q_c is stable
    assert rw.tilt_window(20.0, 8.9, 37.55)[0] != rw.tilt_window(20.0, 8.9, 37.55)[0]  # NaN
    assert rw.tilt_window(60.0, 8.9, 37.55)[1] == 90.0
    with pytest.raises(ValueError, match="g0"):
        rw.tilt_window(-1.0, 8.9, 37.55)


def test_classify_rest():
    window = rw.RestWindow(n=16, w=10.0, q_circle=8.9, losses=(
        rw.StabilityLoss(q=37.55, kind="hopf", sector="out-of-plane", frequency=22.0),))
    low, high = window.tilts(350.0)
    assert rw.classify_rest(low - 0.1, 350.0, window) == "below"
    assert rw.classify_rest(low + 0.1, 350.0, window) == "inside"
    assert rw.classify_rest(high + 0.1, 350.0, window) == "outside"
    assert rw.classify_rest(45.0, 20.0, window) == "below"     # no branch at g0 = 20
    assert rw.classify_rest(float("nan"), 350.0, window) is None


def test_cli_prints_the_window_as_json():
    # a coarse branch (n = 8) keeps it quick: its first loss is still the out-of-plane Hopf
    out = subprocess.run([sys.executable, "-m", "loopsim", "rest-window", "--g0", "350,20",
                          "--n", "8", "--json"], capture_output=True, text=True, check=True)
    data = json.loads(out.stdout)
    first = data["losses"][0]
    assert (first["kind"], first["sector"], data["n"]) == ("hopf", "out-of-plane", 8)
    assert first["q"] == data["q_loss"]
    high = data["windows"][0]["theta_high_deg"]
    assert 350 * math.sin(math.radians(high)) / 3 == pytest.approx(first["q"])
    assert data["windows"][1]["theta_low_deg"] is None      # g0 = 20 < 3 q_c: NaN -> null


def test_the_committed_window_table_is_the_codes(window):
    """data/rest_window.json (whose numbers docs/stability.md renders) is what the code
    computes now: ``loopsim rest-window --g0 10:350:15 --json``."""
    import os

    import numpy as np

    path = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                        "data", "rest_window.json")
    with open(path, encoding="utf-8") as handle:
        committed = json.load(handle)
    now = window.as_dict(np.linspace(10.0, 350.0, 15))
    assert committed["n"] == now["n"] and len(committed["losses"]) == len(now["losses"])
    for a, b in zip(committed["losses"], now["losses"]):
        assert (a["kind"], a["sector"]) == (b["kind"], b["sector"])
        assert a["q"] == pytest.approx(b["q"], abs=1e-8)
    for a, b in zip(committed["windows"], now["windows"]):
        assert a["g0"] == pytest.approx(b["g0"])
        for key in ("theta_low_deg", "theta_high_deg"):
            assert (a[key] is None and b[key] is None) or a[key] == pytest.approx(b[key], abs=1e-7)


def test_a_computed_window_is_kept_and_read_back(tmp_path, monkeypatch):
    """The window is kept beside the kernels and read back equal; a damaged file is
    computed anew (n = 8: seconds)."""
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    compute = rw.stability_losses.__wrapped__            # past the in-process lru_cache
    first = compute(8)
    path = rw.cache_path(8, 10.0, 80.0, 1e-10)
    assert os.path.isfile(path) and str(tmp_path) in path
    assert compute(8).as_dict() == first.as_dict()        # read back: the same losses
    with open(path, "w", encoding="utf-8") as handle:
        handle.write("{not json")
    assert compute(8).losses[0].q == first.losses[0].q    # recomputed
    assert json.load(open(path, encoding="utf-8"))["q_loss"] == first.q_loss
