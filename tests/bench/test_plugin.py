"""``ipmc-asym bench`` through the entry point group ``ipmc_asym.commands``: discovery (with a
monkeypatched ``entry_points``), ``--help`` and options, and ``figures`` finding the measurement
(a run through ``main``: tests/bench/test_suite.py)."""

from __future__ import annotations

from importlib.metadata import EntryPoint

import pytest

import ipmc_asym.cli as cli

BENCH_EP = EntryPoint(name="bench", value="ipmc_asym_bench.cli", group=cli.PLUGIN_GROUP)


def fake_entry_points(*eps):
    def entry_points(**kw):
        return [ep for ep in eps if ep.group == kw.get("group")]

    return entry_points


@pytest.fixture
def with_bench(monkeypatch):
    monkeypatch.setattr(cli, "entry_points", fake_entry_points(BENCH_EP))


@pytest.fixture
def without_plugins(monkeypatch):
    monkeypatch.setattr(cli, "entry_points", fake_entry_points())


def test_bench_is_discovered_and_listed(with_bench, capsys):
    assert set(cli.plugin_commands()) == {"bench"}
    with pytest.raises(SystemExit) as ex:
        cli.main(["--help"])
    assert ex.value.code == 0
    out = capsys.readouterr().out
    assert "bench" in out and "time and accuracy of each fidelity" in out


def test_without_the_plugin_bench_is_unknown(without_plugins, capsys):
    assert cli.plugin_commands() == {} and cli.load_plugin("bench") is None
    with pytest.raises(SystemExit) as ex:
        cli.main(["bench"])
    assert ex.value.code == 2
    assert "bench" not in cli.build_parser()[0].format_help().split("options:")[0].split("COMMAND ...")[-1]


def test_a_plugin_cannot_take_over_a_library_command(monkeypatch):
    monkeypatch.setattr(cli, "entry_points", fake_entry_points(
        EntryPoint(name="estimate", value="ipmc_asym_bench.cli", group=cli.PLUGIN_GROUP)))
    assert cli.plugin_commands() == {}


def test_a_broken_plugin_leaves_the_others_working(monkeypatch, capsys):
    monkeypatch.setattr(cli, "entry_points", fake_entry_points(
        EntryPoint(name="broken", value="no_such_module_here", group=cli.PLUGIN_GROUP)))
    ap, _ = cli.build_parser("laws")
    assert "broken" in ap.format_help()
    assert cli.main(["broken"]) == 2
    assert "cannot be loaded" in capsys.readouterr().err


def test_bench_options(with_bench):
    ap, handlers = cli.build_parser("bench")
    args = ap.parse_args(["bench", "--json", "--points", "1e3", "--bvp-points", "2", "--no-compile", "--layout",
                          "random", "--section", "uq", "--section", "charge", "--quick", "--figure", ""])
    assert (args.points, args.bvp_points, args.no_compile, args.layout, args.section, args.quick, args.figure) == \
        (1000, 2, True, "random", ["uq", "charge"], True, "")
    assert handlers["bench"].__module__ == "ipmc_asym_bench.cli"


@pytest.mark.parametrize("plugin", [True, False])
def test_figures_measures_through_the_plugin_or_skips(plugin, monkeypatch, tmp_path, request):
    request.getfixturevalue("with_bench" if plugin else "without_plugins")
    seen = {}

    def make_all(out, dpi, quick, bench, log, fmt="png"):
        seen["bench"] = bench
        notes = [] if bench is not None else ["speed_accuracy.png skipped: no bench result"]
        return {"files": [], "notes": notes}

    import ipmc_asym.plotting.figures as pf

    monkeypatch.setattr(pf, "make_all", make_all)
    assert cli.main(["figures", "--out", str(tmp_path / "f")]) == 0
    if plugin:
        from ipmc_asym_bench.cli import speed_accuracy_data

        assert seen["bench"] is speed_accuracy_data
    else:
        assert seen["bench"] is None
