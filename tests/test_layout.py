"""Package layout, read with ``ast`` (nothing is imported): the module import graph of
loopsim/ has no cycles, no code uses another loopsim module's private names, and no
module is longer than ``MAX_MODULE_LINES`` physical lines.

Modules are named by their path (``loopsim/foo/__init__.py`` is ``loopsim.foo``).
Every import statement counts, including those inside functions.  An import
``from P import x`` is an edge to ``P.x`` when that is a module of the package
(a submodule), otherwise to ``P`` (a name defined in ``P``), so
``from .base import y`` in loopsim/models/local_sbt.py is an edge to
loopsim.models.base and ``from . import circle`` in loopsim/stability/onset.py
one to loopsim.stability.full_linear.

A private name is one with a single leading underscore (dunders are public).
Private functions, classes and variables may be used only inside the module
that defines them; a private module (``loopsim/_jitcache.py``) only inside its
package, plus the unit tests listed in ``PRIVATE_MODULE_UNIT_TESTS``.
"""
import ast
import os

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PACKAGE = "loopsim"

#: Client files allowed to import one private loopsim module, to unit-test it.
PRIVATE_MODULE_UNIT_TESTS = {"tests/test_jitcache.py": {"loopsim._jitcache"},
                             "tests/test_moved.py": {"loopsim._moved"}}
#: The most physical lines a module of the package may have (issue 23, "Layout").
MAX_MODULE_LINES = 500
#: The most lines of code (not blank, not comments, not the docstring) a function may have
#: (issue 45): a screen.  Numba kernels are exempt (splitting one may change its compiled
#: numerics), and so is a function whose docstring says why it is longer ("Longer than a
#: screen: ...").
MAX_FUNCTION_LINES = 60
#: Decorators that make a function a Numba kernel (``jit.kernel``, ``jit.entry``,
#: ``dispatch.implements``, Numba's own).
KERNEL_DECORATORS = ("kernel", "entry", "implements", "njit", "jit", "overload", "intrinsic")


# ---- reading the package ------------------------------------------------------------

def package_modules(root=ROOT, package=PACKAGE):
    """{dotted module name: (path, is_package)} for every .py file below root/package."""
    modules = {}
    for directory, dirs, files in os.walk(os.path.join(root, package)):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__")
        for name in sorted(files):
            if not name.endswith(".py"):
                continue
            path = os.path.join(directory, name)
            parts = os.path.relpath(path, root)[:-3].split(os.sep)
            is_package = parts[-1] == "__init__"
            if is_package:
                parts = parts[:-1]
            modules[".".join(parts)] = (path, is_package)
    return modules


def _is_private(name):
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def _base_of(module, is_package, node):
    """Absolute module named by ``from ... import`` node (relative levels resolved)."""
    if node.level == 0:
        return node.module
    parts = module.split(".") if is_package else module.split(".")[:-1]
    if node.level > 1:
        parts = parts[: len(parts) - (node.level - 1)]
    return ".".join(parts + ([node.module] if node.module else []))


def imports(module, is_package, tree, known):
    """(line, imported module, imported name or None) for every import in tree that
    targets a module in ``known``; name is the object imported from that module.

    ``import a.b.c`` imports module a.b.c; ``from P import x`` imports module P.x
    when it is known (name None), else the name x of module P.
    """
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name in known:
                    found.append((node.lineno, alias.name, None))
        elif isinstance(node, ast.ImportFrom):
            base = _base_of(module, is_package, node)
            for alias in node.names:
                if f"{base}.{alias.name}" in known:
                    found.append((node.lineno, f"{base}.{alias.name}", None))
                elif base in known:
                    found.append((node.lineno, base, None if alias.name == "*" else alias.name))
    return found


def import_graph(sources, known):
    """{module: {imported modules}} from {module: (source text, is_package)}; self-edges
    (a package __init__ importing its own names) are dropped."""
    graph = {}
    for module, (text, is_package) in sources.items():
        tree = ast.parse(text)
        graph[module] = {target for _, target, _ in imports(module, is_package, tree, known)
                         if target != module}
    return graph


def find_cycle(graph):
    """One import cycle [m0, m1, ..., m0] of graph, or None (iterative DFS)."""
    state = {}  # 1 = on the current path, 2 = finished
    for start in sorted(graph):
        if start in state:
            continue
        path, stack = [start], [iter(sorted(graph.get(start, ())))]
        state[start] = 1
        while stack:
            nxt = next(stack[-1], None)
            if nxt is None:
                state[path.pop()] = 2
                stack.pop()
            elif state.get(nxt) == 1:
                return path[path.index(nxt):] + [nxt]
            elif nxt not in state:
                state[nxt] = 1
                path.append(nxt)
                stack.append(iter(sorted(graph.get(nxt, ()))))
    return None


def private_uses(module, is_package, tree, known, where, allowed_modules=()):
    """(where:line, name) for each private name of another loopsim module used in tree.

    module is the dotted name of the file (None for a client outside the package).
    Covers ``from M import _x``, ``import M._x`` / ``from P import _m`` for private
    modules, and attribute access ``alias._x`` where alias (or a dotted chain of
    attributes from it) denotes a loopsim module.
    """
    def foreign_private_module(target):
        """A private module (some part of its name) not within the user's own package."""
        parts = target.split(".")
        for i, part in enumerate(parts):
            if _is_private(part):
                owner = ".".join(parts[:i])  # the package the private module belongs to
                inside = module is not None and (module == owner or module.startswith(owner + "."))
                if not inside and target not in allowed_modules:
                    return True
        return False

    offenders = []
    aliases = {}  # local name -> loopsim module it denotes
    for line, target, name in imports(module, is_package, tree, known):
        if name is None:
            if foreign_private_module(target):
                offenders.append((f"{where}:{line}", target))
        elif _is_private(name) and target != module:
            offenders.append((f"{where}:{line}", f"{target}.{name}"))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.asname:
                    if alias.name in known:
                        aliases[alias.asname] = alias.name
                else:
                    top = alias.name.split(".")[0]
                    if top in known:
                        aliases[top] = top
        elif isinstance(node, ast.ImportFrom):
            base = _base_of(module, is_package, node)
            for alias in node.names:
                if f"{base}.{alias.name}" in known:
                    aliases[alias.asname or alias.name] = f"{base}.{alias.name}"

    def resolve(expr):
        """The loopsim module an expression (Name or Attribute chain) denotes, or None."""
        if isinstance(expr, ast.Name):
            return aliases.get(expr.id)
        if isinstance(expr, ast.Attribute):
            owner = resolve(expr.value)
            if owner is not None and f"{owner}.{expr.attr}" in known:
                return f"{owner}.{expr.attr}"
        return None

    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and _is_private(node.attr):
            owner = resolve(node.value)
            if owner is None or owner == module:
                continue
            target = f"{owner}.{node.attr}"
            if target not in known or foreign_private_module(target):
                offenders.append((f"{where}:{node.lineno}", target))
    return sorted(set(offenders))


def _read(path):
    with open(path, encoding="utf-8") as handle:
        return handle.read()


def _format(offenders):
    return "\n".join(f"  {place}: {name}" for place, name in offenders)


# ---- the checks on the package --------------------------------------------------------

def test_import_graph_has_no_cycles():
    modules = package_modules()
    sources = {name: (_read(path), is_package) for name, (path, is_package) in modules.items()}
    graph = import_graph(sources, set(modules))
    cycle = find_cycle(graph)
    assert cycle is None, "import cycle: " + " -> ".join(cycle)


def test_no_module_is_over_the_line_limit():
    """Every .py file of the package has at most MAX_MODULE_LINES physical lines (one job
    per module)."""
    over = []
    for name, (path, _) in sorted(package_modules().items()):
        with open(path, encoding="utf-8") as handle:
            lines = sum(1 for _ in handle)
        if lines > MAX_MODULE_LINES:
            over.append(f"  {os.path.relpath(path, ROOT)}: {lines} lines")
    assert not over, (f"modules over {MAX_MODULE_LINES} lines (split them by job):\n"
                      + "\n".join(over))


def test_package_uses_no_private_names_of_other_modules():
    modules = package_modules()
    offenders = []
    for name, (path, is_package) in modules.items():
        tree = ast.parse(_read(path), filename=path)
        offenders += private_uses(name, is_package, tree, set(modules), os.path.relpath(path, ROOT))
    assert not offenders, "private names of other loopsim modules used:\n" + _format(offenders)


@pytest.mark.parametrize("folder", ["tests", "scripts", "benchmarks"])
def test_clients_use_no_private_loopsim_names(folder):
    """Tests, scripts and benchmarks use loopsim through its public names only."""
    known = set(package_modules())
    directory = os.path.join(ROOT, folder)
    offenders = []
    for name in sorted(os.listdir(directory)):
        if name.endswith(".py"):
            path = os.path.join(directory, name)
            where = f"{folder}/{name}"
            tree = ast.parse(_read(path), filename=path)
            offenders += private_uses(None, False, tree, known, where,
                                      PRIVATE_MODULE_UNIT_TESTS.get(where, ()))
    assert not offenders, f"private loopsim names used in {folder}/:\n" + _format(offenders)


def code_lines(lines, node):
    """Lines of code of a function node: not blank, not comment-only, docstring left out."""
    body = node.body
    first = body[0]
    docstring = (isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant)
                 and isinstance(first.value.value, str))
    if docstring and len(body) == 1:
        return 0
    start = body[1].lineno if docstring else first.lineno
    return sum(1 for line in lines[start - 1:node.end_lineno]
               if line.strip() and not line.strip().startswith("#"))


def is_kernel(node):
    for decorator in node.decorator_list:
        target = decorator.func if isinstance(decorator, ast.Call) else decorator
        name = target.attr if isinstance(target, ast.Attribute) else getattr(target, "id", "")
        if name in KERNEL_DECORATORS:
            return True
    return False


def test_no_function_is_longer_than_a_screen():
    """Every function of the package outside Numba kernels has at most
    MAX_FUNCTION_LINES lines of code, or says in its docstring why not."""
    over = []
    for name, (path, _) in sorted(package_modules().items()):
        text = _read(path)
        lines = text.splitlines()
        for node in ast.walk(ast.parse(text, filename=path)):
            if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) or is_kernel(node):
                continue
            count = code_lines(lines, node)
            if count > MAX_FUNCTION_LINES and \
                    "Longer than a screen:" not in (ast.get_docstring(node) or ""):
                over.append(f"  {os.path.relpath(path, ROOT)}:{node.lineno} {node.name}: "
                            f"{count} lines")
    assert not over, (f"functions over {MAX_FUNCTION_LINES} lines of code (split them along "
                      "their steps):\n" + "\n".join(over))


def test_code_lines_count_what_they_say():
    source = ('def f():\n    """Doc\n\n    more."""\n    a = 1\n\n    # note\n    return a\n'
              "def g():\n    return 2\n")
    tree = ast.parse(source)
    lines = source.splitlines()
    assert [code_lines(lines, node) for node in tree.body] == [2, 1]
    kernel = ast.parse("@kernel\ndef k():\n    pass\n@numba.njit(cache=True)\ndef j():\n"
                       "    pass\ndef p():\n    pass\n")
    assert [is_kernel(node) for node in kernel.body] == [True, True, False]


def _layers():
    """The layers named in loopsim/__init__.py's docstring (scripts/module_table.py)."""
    return module_table_script().layers()


def module_table_script():
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "module_table", os.path.join(ROOT, "scripts", "module_table.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_layer_list_names_every_module_once_and_imports_go_up_only():
    """loopsim/__init__.py names every top-level module and subpackage in its list of
    layers, once; every import goes to a module of an earlier layer."""
    layer_of = {}
    for number, names in enumerate(_layers()):
        for name in names:
            assert name not in layer_of, f"{name} named twice"
            layer_of[name] = number
    modules = package_modules()
    top = {m.split(".")[1] for m in modules if m != PACKAGE}
    assert set(layer_of) == top, (f"not named: {sorted(top - set(layer_of))}; "
                                  f"no such module: {sorted(set(layer_of) - top)}")
    sources = {name: (_read(path), is_package) for name, (path, is_package) in modules.items()}
    upward = []
    for module, targets in import_graph(sources, set(modules)).items():
        if module == PACKAGE:
            continue
        here = module.split(".")[1]
        for target in targets:
            there = target.split(".")[1] if target != PACKAGE else None
            if there is not None and there != here and layer_of[there] >= layer_of[here]:
                upward.append(f"  {module} imports {target} (layer {layer_of[there] + 1} >= "
                              f"{layer_of[here] + 1})")
    assert not upward, "imports of a module not in an earlier layer:\n" + "\n".join(upward)


def test_extending_md_module_table_is_current():
    assert module_table_script().main(["--check"]) == 0, \
        "docs/extending.md's module table is stale: run python scripts/module_table.py"


# ---- the checker itself, on synthetic sources ---------------------------------------

KNOWN = {"pkg", "pkg.a", "pkg.sub", "pkg.sub.b", "pkg.sub.c", "pkg._hidden"}


def _edges(module, is_package, text):
    return {target for _, target, _ in imports(module, is_package, ast.parse(text), KNOWN)}


def test_relative_imports_resolve_to_submodules_or_packages():
    code = "from . import c\nfrom .b import f\nfrom .. import a\nfrom ..sub import g\n"
    assert _edges("pkg.sub.b", False, code) == {"pkg.sub.c", "pkg.sub.b", "pkg.a", "pkg.sub"}
    # in a package __init__ the level-1 base is the package itself
    assert _edges("pkg.sub", True, "from . import b\nfrom .c import h\n") == {"pkg.sub.b", "pkg.sub.c"}
    assert _edges("pkg.a", False, "def f():\n    import pkg.sub.c\n    from pkg import sub\n") == {
        "pkg.sub.c", "pkg.sub"}
    assert _edges("pkg.a", False, "import numpy\nfrom os import path\n") == set()


def test_cycle_finder_reports_the_cycle():
    sources = {
        "pkg": ("from . import a\n", True),
        "pkg.a": ("from .sub import helper\n", False),
        "pkg.sub": ("from . import b, c\n", True),
        "pkg.sub.b": ("", False),
        "pkg.sub.c": ("def late():\n    from ..a import x\n", False),
    }
    graph = import_graph(sources, KNOWN)
    cycle = find_cycle(graph)
    assert cycle is not None and cycle[0] == cycle[-1]
    assert set(cycle) == {"pkg.a", "pkg.sub", "pkg.sub.c"}
    sources["pkg.sub.c"] = ("from . import b\n", False)
    assert find_cycle(import_graph(sources, KNOWN)) is None


def test_private_use_finder_flags_each_form():
    code = (
        "import pkg\nimport pkg.sub.b as bee\nfrom pkg.sub import c\nfrom pkg.a import _x, y\n"
        "from pkg import _hidden\n"
        "pkg.sub.b._f()\nbee._g\nc._h\nc.y._z\nbee.__doc__\npkg._hidden.run()\n"
    )
    found = private_uses(None, False, ast.parse(code), KNOWN, "t.py")
    assert found == [("t.py:11", "pkg._hidden"), ("t.py:4", "pkg.a._x"), ("t.py:5", "pkg._hidden"),
                     ("t.py:6", "pkg.sub.b._f"), ("t.py:7", "pkg.sub.b._g"),
                     ("t.py:8", "pkg.sub.c._h")]
    # inside the package: own private names and the package's private module are fine
    own = "from . import _hidden\nfrom .a import _x\nimport pkg\npkg._hidden.run()\n"
    assert private_uses("pkg.a", False, ast.parse(own), KNOWN, "pkg/a.py") == []
    assert private_uses("pkg.sub.b", False, ast.parse("from .c import _q\n"), KNOWN, "b.py") == [
        ("b.py:1", "pkg.sub.c._q")]
    # an allowed unit test of a private module
    assert private_uses(None, False, ast.parse("from pkg import _hidden\n"), KNOWN, "t.py",
                        {"pkg._hidden"}) == []


def test_cli_names_the_integrators_and_loads_no_kernels_for_help():
    """`loopsim --help` loads neither NumPy nor Numba (measured 0.04-0.08 s); the
    command line's list of integrators is the integrators' own."""
    import subprocess
    import sys

    from loopsim import cli, integrators

    assert cli.METHODS == tuple(sorted(integrators.METHODS))
    code = ("import sys, loopsim.cli as c\n"
            "try:\n    c.main(['--help'])\nexcept SystemExit:\n    pass\n"
            "print(sorted(m for m in ('numpy', 'numba', 'pandas') if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=True)
    assert done.stdout.strip().splitlines()[-1] == "[]"
