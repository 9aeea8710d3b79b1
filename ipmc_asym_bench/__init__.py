"""Speed/accuracy benchmark of ``ipmc_asym`` (``ipmc-asym bench``), outside the library.

One module per section: :mod:`~ipmc_asym_bench.suite` (the runner, the table, the section
registry), :mod:`~ipmc_asym_bench.kernels` (kernel cost per point, compile and start-up
times, the BVP sample), :mod:`~ipmc_asym_bench.exact`, :mod:`~ipmc_asym_bench.commands`,
:mod:`~ipmc_asym_bench.distributed`, :mod:`~ipmc_asym_bench.uq`,
:mod:`~ipmc_asym_bench.charge`; :mod:`~ipmc_asym_bench.cli` is the ``bench`` command,
found by ``ipmc-asym`` through the entry point group ``ipmc_asym.commands``.  Only the
public API of ``ipmc_asym`` is used, and nothing in ``ipmc_asym`` imports this package.
"""
