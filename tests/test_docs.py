"""The documentation site (mkdocs.yml, docs/) builds in strict mode: a broken link, a
missing #anchor or an API reference to a name that no longer exists fails the suite.
The API page is read from the source by mkdocstrings (griffe, statically: nothing of
loopsim is imported)."""
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def test_docs_build_strict(tmp_path):
    site = tmp_path / "site"
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")  # Material's notice about its end of life
    run = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)],
        cwd=ROOT, env=env, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    assert (site / "index.html").is_file()
    api = site / "api" / "index.html"
    assert api.is_file()
    assert "simulate" in api.read_text(encoding="utf-8")
