"""simulate's and sweep's numpydoc parameter blocks: the parameters they share are
described in the same words, and every documented default is the signature's.

Two copies, because the API page is rendered statically from the source by
mkdocstrings: a docstring assembled at run time would show there unassembled."""
import inspect
import math
import re

import pytest

import loopsim
from loopsim.outcomes import Thresholds

#: The parameters with the same meaning in both functions.
SHARED = ("rtol", "atol", "w", "method", "twin", "n_max", "tail_tol", "model", "slenderness",
          "max_steps", "length_tol", "steady_interval")
FUNCTIONS = (loopsim.simulate, loopsim.sweep)


def parameter_blocks(function):
    """{names: (header, description)} of the docstring's Parameters section."""
    doc = inspect.getdoc(function)
    section = doc.split("Parameters\n----------\n", 1)[1].split("\n\n", 1)[0]
    blocks = {}
    for match in re.finditer(r"^(\S[^\n]*?) : ([^\n]*)\n((?:    [^\n]*\n?)*)", section, re.M):
        names = tuple(n.strip() for n in match.group(1).split(","))
        blocks[names] = (match.group(2), match.group(3).rstrip())
    return blocks


def documented_defaults(header, count):
    """The defaults a header states, one per name (one stated for all, or one each)."""
    text = header.split(", default ", 1)[1]
    namespace = {"inf": math.inf, "Thresholds": Thresholds, "__builtins__": {}}
    values = eval(f"({text},)", namespace)  # noqa: S307: the repository's own docstrings
    if count > 1 and len(values) == 1:
        values = values * count
    if count == 1 and len(values) > 1:
        values = (values,)  # a tuple default such as (0.0, 10.0)
    assert len(values) == count, header
    return values


@pytest.mark.parametrize("name", SHARED)
def test_shared_parameters_read_the_same(name):
    simulate_text, sweep_text = (parameter_blocks(f).get((name,)) for f in FUNCTIONS)
    assert simulate_text is not None and sweep_text is not None, name
    assert simulate_text == sweep_text, name


@pytest.mark.parametrize("function", FUNCTIONS, ids=lambda f: f.__name__)
def test_documented_defaults_are_the_signatures(function):
    signature = inspect.signature(function).parameters
    blocks = parameter_blocks(function)
    documented = {name for names in blocks for name in names}
    assert documented == set(signature), documented ^ set(signature)
    for names, (header, _) in blocks.items():
        defaults = [signature[name].default for name in names]
        if all(d is inspect.Parameter.empty for d in defaults):
            assert ", default " not in header, names
            continue
        assert documented_defaults(header, len(names)) == tuple(defaults), (names, header)


def test_twin_cost_is_not_understated():
    for function in FUNCTIONS:
        assert "about doubles" not in inspect.getdoc(function)
