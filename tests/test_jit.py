"""The Numba cache is keyed on every module that defines jitted code."""

import re
from pathlib import Path

import ipmc_asym
from ipmc_asym import _jit


def test_cache_key_covers_every_jitted_module():
    root = Path(ipmc_asym.__file__).parent
    jitted = {p.resolve() for p in root.rglob("*.py")
              if re.search(r"^@(jit|jit_parallel)\b", p.read_text(), re.M)}
    assert jitted, "no jitted modules found"
    assert jitted <= {p.resolve() for p in _jit.hashed_sources()}


def test_flags_set_in_one_place():
    root = Path(ipmc_asym.__file__).parent
    offenders = [p.name for p in root.rglob("*.py") if p.name != "_jit.py"
                 and re.search(r"numba\.(n)?jit\(|@(nb|numba)\.(n)?jit", p.read_text())]
    assert offenders == []
