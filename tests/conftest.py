import os

import numpy as np

np.seterr(all="raise", under="ignore")


def pytest_addoption(parser):
    parser.addoption("--update-golden", action="store_true", default=False,
                     help="rewrite the golden files (validate verdicts) from this run instead of comparing")


def pytest_configure(config):
    # the generated kernels have their own compare-or-update: ipmc-asym derive [--check]
    config.update_golden = config.getoption("--update-golden")
    if os.environ.get("PYTEST_XDIST_WORKER"):
        # one BLAS thread per test worker (and its subprocesses): the workers share the cores, and
        # OpenBLAS's threads spin between calls, so a second BLAS thread per worker only competes with
        # the other worker (measured, -n 2 on 2 cores, -m "not slow": 154-163 s with the default
        # threads, 131 s with one).  Numba's threads are left alone: the tests of the package's own
        # thread rule set them.
        from threadpoolctl import threadpool_limits

        config.blas_limit = threadpool_limits(limits=1, user_api="blas")
        os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


def _declared_commands_entry_points():
    """The ``ipmc_asym.commands`` entry points of pyproject.toml, added to what ``ipmc_asym.cli``
    discovers when the installed metadata predates them (an editable install made before
    they were declared): the tests run the commands this tree declares."""
    from importlib.metadata import EntryPoint
    from pathlib import Path

    try:
        import tomllib
    except ImportError:  # Python 3.10
        import tomli as tomllib

    import ipmc_asym.cli as cli

    data = tomllib.loads((Path(__file__).resolve().parents[1] / "pyproject.toml").read_text(encoding="utf-8"))
    declared = data.get("project", {}).get("entry-points", {}).get(cli.PLUGIN_GROUP, {})
    missing = [EntryPoint(name=k, value=v, group=cli.PLUGIN_GROUP) for k, v in declared.items()
               if k not in cli.plugin_commands()]
    if not missing:
        return
    installed = cli.entry_points

    def entry_points(**kw):
        eps = list(installed(**kw))
        return eps + missing if kw.get("group") == cli.PLUGIN_GROUP else eps

    cli.entry_points = entry_points


_declared_commands_entry_points()
