"""The package's public face: a small ``__all__``, a lazy import that leaves the import machinery
alone, and no module paths of the flat layout."""

from __future__ import annotations

import importlib
import inspect
import subprocess
import sys

import pytest

import ipmc_asym

#: module paths of the flat layout (before the subpackages); removed, not aliased
FLAT_PATHS = ("registry", "settings", "units", "progress", "params", "permittivity", "_jit", "bvp_mesh",
              "bvp_problems", "integral_samples", "fileio", "jsonio", "textfmt", "datasets", "estimate",
              "electrode", "transient", "circuit", "executors", "sweeps", "fits", "scene_schema", "scenes",
              "charge_studies", "calibrate")


def _in_fresh_interpreter(code: str) -> str:
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    return out.stdout.strip()


def test_public_api_is_small_and_resolves():
    assert 30 <= len(ipmc_asym.__all__) <= 60
    assert len(set(ipmc_asym.__all__)) == len(ipmc_asym.__all__)
    for name in ipmc_asym.__all__:
        obj = getattr(ipmc_asym, name)
        assert not inspect.ismodule(obj), name


def test_import_changes_no_import_machinery_and_loads_nothing_heavy():
    code = ("import sys; before = list(sys.meta_path), list(sys.path_hooks); import ipmc_asym; "
            "print(before == (list(sys.meta_path), list(sys.path_hooks)), "
            "sorted({m.split('.')[0] for m in sys.modules} & {'numba', 'scipy', 'sympy', 'matplotlib'}))")
    assert _in_fresh_interpreter(code) == "True []"


@pytest.mark.parametrize("old", FLAT_PATHS)
def test_flat_module_paths_are_gone(old):
    with pytest.raises(ModuleNotFoundError):
        importlib.import_module(f"ipmc_asym.{old}")


def test_unknown_attribute_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'params'"):
        ipmc_asym.params  # noqa: B018


def test_result_types_are_public():
    """Every result type the public functions return is exported under its own name."""
    names = {"MomentResult", "BVPResult", "BeamResult", "ForwardResult", "ChargeResult", "StepResult",
             "FrequencyResult", "LineResult", "RationalModel", "CalibrationResult", "UQResult", "DesignResult"}
    assert names <= set(ipmc_asym.__all__)
    for n in names:
        assert inspect.isclass(getattr(ipmc_asym, n)) and getattr(ipmc_asym, n).__name__ == n
    assert inspect.signature(ipmc_asym.moment).return_annotation in ("MomentResult", ipmc_asym.MomentResult)
