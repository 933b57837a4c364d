"""A first compile of the kernels is said once; a later process loads them from numba's on-disk cache."""

import os
import subprocess
import sys

_CODE = """
from htetro_opt._jit import on_compile
said = []
on_compile(said.append)
from htetro_opt.operators.commands.shortcut import longest_loops
import numpy as np
longest_loops(np.array([[0, 1, 2, 1, 3]]), np.array([4]))
longest_loops(np.array([[0, 1, 0]]), np.array([2]))
print(len(said))
"""


def test_a_first_compile_is_said_once_and_a_second_process_loads_from_the_cache(tmp_path):
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}  # a fresh cache: the first process compiles
    runs = [subprocess.run([sys.executable, "-c", _CODE], capture_output=True, text=True, check=True, env=env)
            for _ in range(2)]
    assert [r.stdout.strip() for r in runs] == ["1", "0"]
    assert any(tmp_path.rglob("*.nbi"))  # numba's index of the cached kernel
