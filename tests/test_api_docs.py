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


def test_the_examples_that_run_do_what_they_say():
    """Doctests of the public names (those marked +SKIP need a sweep directory or minutes)."""
    finder, runner = doctest.DocTestFinder(recurse=False), doctest.DocTestRunner(
        optionflags=doctest.ELLIPSIS)
    ran = 0
    for name in FUNCTIONS + CLASSES:
        for test in finder.find(getattr(loopsim, name), name):
            ran += sum(not example.options.get(doctest.SKIP) for example in test.examples)
            runner.run(test)
    assert runner.failures == 0 and ran >= 6


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
