import numpy as np

np.seterr(all="raise", under="ignore")


def pytest_addoption(parser):
    parser.addoption("--update-golden", action="store_true", default=False,
                     help="rewrite the golden files (validate verdicts) from this run instead of comparing")


def pytest_configure(config):
    # the generated kernels have their own compare-or-update: ipmc-asym derive [--check]
    config.update_golden = config.getoption("--update-golden")
