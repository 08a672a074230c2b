"""The old import paths of renamed modules (``loopsim._moved``, CHANGELOG.md "Unreleased")
work for one release: each warns (``DeprecationWarning``) and is the new module itself."""
import importlib
import subprocess
import sys

import pytest

import loopsim
from loopsim import _moved  # noqa: the deprecation table is tested as a unit

ONE_TO_ONE = {old: new[0] for old, new in _moved.MOVED.items() if len(new) == 1}


def _fresh_import(name):
    sys.modules.pop(name, None)
    with pytest.warns(DeprecationWarning, match=name.replace(".", r"\.")):
        return importlib.import_module(name)


@pytest.mark.parametrize("old", sorted(ONE_TO_ONE))
def test_an_old_path_warns_and_is_the_new_module(old):
    assert _fresh_import(old) is importlib.import_module(ONE_TO_ONE[old])


def test_a_moved_package_takes_its_submodules_along():
    assert _fresh_import("loopsim.io.tables") is importlib.import_module("loopsim.storage.tables")


def test_the_split_config_finds_each_name_in_its_new_home():
    from loopsim import defaults, exit_codes, jit

    config = _fresh_import("loopsim.config")
    assert config.DEFAULT_W is defaults.DEFAULT_W
    assert config.ENVIRONMENT_ERRNOS is exit_codes.ENVIRONMENT_ERRNOS
    assert config.JIT is jit.JIT
    with pytest.raises(AttributeError):
        config.NO_SUCH_NAME


def test_the_old_function_names_warn():
    from loopsim import batch

    with pytest.warns(DeprecationWarning, match="integrate_batch"):
        assert batch.integrate_cases is batch.integrate_batch


def test_every_new_module_exists_and_no_file_is_left_at_an_old_path():
    import os

    root = os.path.dirname(loopsim.__file__)
    for old, new in _moved.MOVED.items():
        rel = os.path.join(*old.split(".")[1:])
        assert not os.path.exists(os.path.join(root, rel + ".py")), old
        assert not os.path.isdir(os.path.join(root, rel)), old
        for name in new:
            importlib.import_module(name)


def test_the_command_line_loads_the_finder_without_numpy():
    code = ("import sys, loopsim.cli\n"
            "print('numpy' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=True)
    assert done.stdout.strip() == "False"


@pytest.mark.parametrize("old", sorted(_moved.MOVED) + ["loopsim.io.tables", "loopsim.ensemble"])
def test_star_import_of_an_old_path_gives_its_public_names_and_warns(old):
    """``from OLD import *`` warns and binds the old public names, each the new object
    (issue 54.12: ``from loopsim.config import *`` bound none)."""
    sys.modules.pop(old, None)
    namespace = {}
    with pytest.warns(DeprecationWarning, match=old.replace(".", r"\.")):
        exec(f"from {old} import *", namespace)  # noqa: S102 - the statement under test
    names = {key for key in namespace if not key.startswith("__")}
    if old in _moved.OLD_PUBLIC_NAMES:
        assert names == set(_moved.OLD_PUBLIC_NAMES[old])
        from loopsim import defaults, exit_codes, jit

        assert namespace["DEFAULT_W"] is defaults.DEFAULT_W
        assert namespace["SEED_TARGETS"] is defaults.SEED_TARGETS
        assert namespace["ENVIRONMENT_ERRNOS"] is exit_codes.ENVIRONMENT_ERRNOS
        assert namespace["JIT"] is jit.JIT
    else:
        assert names, f"from {old} import * bound nothing"
