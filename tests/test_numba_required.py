"""numba is a core dependency: without it every compiled path raises one clear, typed error (there is
no pure-Python fallback)."""

import importlib.util
import sys

import pytest

from htetro_opt._jit import lazy_jit, require_numba
from htetro_opt.errors import DependencyError, HtetroError


@lazy_jit
def _twice(x):
    return 2 * x


@pytest.fixture
def without_numba(monkeypatch):
    monkeypatch.setitem(sys.modules, "numba", None)  # makes `import numba` fail, as if not installed


def test_the_error_names_numba_a_core_dependency_and_the_install_command(without_numba):
    with pytest.raises(DependencyError) as info:
        require_numba()
    assert isinstance(info.value, ImportError) and isinstance(info.value, HtetroError)
    assert info.value.name == "numba"
    assert "core dependency" in str(info.value) and "pip install 'numba>=0.59'" in str(info.value)


def test_a_lazily_compiled_loop_raises_at_its_first_call(without_numba):
    with pytest.raises(DependencyError, match="core dependency"):
        _twice(3)


@pytest.mark.parametrize("module", ["htetro_opt.solvers.sequencing._ils", "htetro_opt.solvers.tiling._sweep"])
def test_the_kernel_modules_raise_when_imported(without_numba, module):
    # a fresh copy of the module, so that the one the other tests use stays loaded
    origin = importlib.util.find_spec(module).origin
    spec = importlib.util.spec_from_file_location(f"{module}_without_numba", origin)
    with pytest.raises(DependencyError, match="core dependency"):
        spec.loader.exec_module(importlib.util.module_from_spec(spec))
