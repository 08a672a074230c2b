"""The public API's docstrings are numpydoc: every name of ``loopsim.__all__`` has the
sections a user needs, every parameter of its signature is documented with a type (and
its default), and the examples that run do what they say."""
import doctest
import inspect
import os
import re

import pytest

import loopsim

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
#: Names of ``__all__`` that are data, not callables (documented in docs/api.md).
DATA = ("__version__", "SUMMARY_FIELDS")
FUNCTIONS = [name for name in loopsim.__all__
             if name not in DATA and not inspect.isclass(getattr(loopsim, name))]
CLASSES = [name for name in loopsim.__all__ if inspect.isclass(getattr(loopsim, name))]
#: Sections each kind of public name must have (numpydoc's headings).
FUNCTION_SECTIONS = ("Parameters", "Returns", "Raises", "Examples")
CLASS_SECTIONS = {"SimulationResult": ("Attributes", "Examples"),
                  "LoopsimWarning": ("Examples",)}


def sections(docstring):
    """{heading: body} of a numpydoc docstring: a heading is a line followed by a line of
    dashes of its length (numpydoc's own rule)."""
    lines = inspect.cleandoc(docstring or "").splitlines()
    found, current = {}, None
    for i, line in enumerate(lines):
        underline = lines[i + 1].strip() if i + 1 < len(lines) else ""
        if line.strip() and underline and set(underline) == {"-"} and \
                len(underline) == len(line.strip()):
            current = line.strip()
            found[current] = []
        elif current is not None and not (line.strip() and set(line.strip()) == {"-"}):
            found[current].append(line)
    return found


def parameter_entries(body):
    """{name: type text} of a Parameters section: unindented "name : type" lines (several
    names may share one line, separated by commas)."""
    entries = {}
    for line in body:
        if line and not line[0].isspace():
            names, _, kind = line.partition(" : ")
            for name in names.split(","):
                entries[name.strip()] = kind.strip()
    return entries


def test_sections_parse_numpydoc_headings():
    """The parser finds headings and entries, and misses a section that is not there."""
    text = """Summary.

    Parameters
    ----------
    a, b : float, default 1.0
        Two numbers.

    Returns
    -------
    float
    """
    found = sections(text)
    assert set(found) == {"Parameters", "Returns"}
    assert parameter_entries(found["Parameters"]) == {"a": "float, default 1.0",
                                                      "b": "float, default 1.0"}
    assert "Raises" not in sections("Summary.\n\nRaises: nothing\n")


@pytest.mark.parametrize("name", FUNCTIONS)
def test_every_public_function_has_the_numpydoc_sections(name):
    function = getattr(loopsim, name)
    found = sections(function.__doc__)
    missing = [s for s in FUNCTION_SECTIONS if s not in found]
    assert not missing, f"{name}: no {missing}"
    entries = parameter_entries(found["Parameters"])
    for parameter in inspect.signature(function).parameters.values():
        assert parameter.name in entries, f"{name}: parameter {parameter.name} undocumented"
        kind = entries[parameter.name]
        assert kind, f"{name}: parameter {parameter.name} has no type"
        if parameter.default is not inspect.Parameter.empty:
            assert "default" in kind, f"{name}: parameter {parameter.name} hides its default"
    assert set(entries) <= set(inspect.signature(function).parameters), \
        f"{name}: documents parameters it does not take"
    assert any(line.strip() for line in found["Returns"]) and \
        any(line.strip() for line in found["Raises"])
    assert any(line.lstrip().startswith(">>>") for line in found["Examples"])


@pytest.mark.parametrize("name", CLASSES)
def test_every_public_class_has_its_sections(name):
    found = sections(getattr(loopsim, name).__doc__)
    missing = [s for s in CLASS_SECTIONS[name] if s not in found]
    assert not missing, f"{name}: no {missing}"


def test_simulation_result_documents_every_field_and_property():
    from dataclasses import fields

    entries = parameter_entries(sections(loopsim.SimulationResult.__doc__)["Attributes"])
    public = {f.name for f in fields(loopsim.SimulationResult)} | {
        name for name, value in vars(loopsim.SimulationResult).items()
        if isinstance(value, property)}
    assert public <= set(entries), sorted(public - set(entries))


def test_every_public_name_is_in_the_api_reference():
    with open(os.path.join(ROOT, "docs", "api.md"), encoding="utf-8") as handle:
        text = handle.read()
    for name in loopsim.__all__:
        if name != "__version__":
            assert re.search(rf"[.`]{name}\b", text), name


#: Docstrings whose examples are not run, and why: each takes longer than 2 s.
SKIPPED_EXAMPLES = {
    "loopsim.figures.animation.animate": "draws and encodes a GIF's frames: 8-10 s",
    "loopsim.stability.rest_window.rest_window": "continues the branch to its fold at n = 16: "
                                                 "20 s of one core; its values are checked "
                                                 "in tests/test_rest_window.py",
}


def package_doctests():
    """The doctests of every module of the package (each docstring once)."""
    import importlib
    import pkgutil

    finder, found = doctest.DocTestFinder(), {}
    for info in pkgutil.walk_packages(loopsim.__path__, "loopsim."):
        if info.name.endswith("__main__"):
            continue
        for test in finder.find(importlib.import_module(info.name), info.name):
            if test.examples and test.name not in found:
                found[test.name] = test
    return list(found.values())


def test_every_docstring_example_runs_and_does_what_it_says(tmp_path, monkeypatch):
    """Every example of the package's docstrings runs (in an empty directory, as a user's
    fresh one; the sweeps' examples write runs/ there) and prints what it shows, without
    an unexpected LoopsimWarning (a warning the docs do not show is an error here); only
    the examples of ``SKIPPED_EXAMPLES`` are skipped, each for its reason."""
    import warnings

    monkeypatch.chdir(tmp_path)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    tests = package_doctests()
    skipped = {test.name for test in tests
               if any(example.options.get(doctest.SKIP) for example in test.examples)}
    with warnings.catch_warnings():
        warnings.simplefilter("error", loopsim.LoopsimWarning)
        for test in tests:
            runner.run(test)
    ran = sum(not example.options.get(doctest.SKIP) for test in tests for example in test.examples)
    assert runner.failures == 0
    assert skipped == set(SKIPPED_EXAMPLES), skipped
    assert ran >= 45


def test_the_docstrings_state_the_twins_measured_cost():
    """simulate's and sweep's ``twin`` give the cost docs/studies/n-auto.md measures
    (the twin's RHS evaluations over the run's, median over the README's main job), not
    "about doubles"."""
    with open(os.path.join(ROOT, "docs", "studies", "n-auto.md"), encoding="utf-8") as handle:
        page = " ".join(handle.read().split())
    twin_over_run = float(re.search(r"([\d.]+) times over the README's main job", page).group(1))
    for function in (loopsim.simulate, loopsim.sweep):
        body = sections(function.__doc__)["Parameters"]
        start = next(i for i, line in enumerate(body) if line.startswith("twin :"))
        twin = " ".join(" ".join(body[start:start + 5]).split())
        assert f"about {1 + twin_over_run:.1f} times" in twin, (function.__name__, twin)
        assert "doubles" not in twin


def test_help_opens_with_what_loopsim_is_and_its_entry_points():
    lines = loopsim.__doc__.splitlines()
    assert lines[0].startswith("loopsim: flexible elastic loops sedimenting")
    opening = "\n".join(lines[:25])
    for name in ("simulate", "sweep", "read_results", "summarize", "loopsim --help"):
        assert name in opening, name


def test_sweep_spells_out_its_options_and_refuses_unknown_ones(tmp_path):
    parameters = inspect.signature(loopsim.sweep).parameters
    assert not any(p.kind is inspect.Parameter.VAR_KEYWORD for p in parameters.values())
    for option in ("t_end", "rtol", "twin", "n_max", "tail_tol", "max_seeds", "model"):
        assert parameters[option].kind is inspect.Parameter.KEYWORD_ONLY, option
    with pytest.raises(TypeError, match="colour"):
        loopsim.sweep(10.0, 30.0, tmp_path / "s", colour="red")
    assert not (tmp_path / "s").exists()


def test_mkdocs_renders_numpy_docstrings():
    with open(os.path.join(ROOT, "mkdocs.yml"), encoding="utf-8") as handle:
        assert "docstring_style: numpy" in handle.read()
