"""Progress on stderr: lines (no carriage returns) when stderr is not a terminal, nothing when off."""

import ipmc_asym.base.progress as pr


def test_lines_when_not_a_terminal(monkeypatch, capsys):
    monkeypatch.setattr(pr, "LINE_INTERVAL_S", 0.0)  # every update is "a few seconds later"
    with pr.progress(4, "sweep", unit="row") as bar:  # pytest's stderr is not a terminal
        bar.update(2)
        bar.update(2)
    err = capsys.readouterr().err
    assert err.splitlines() == ["ipmc-asym: sweep: 2/4 row (50 %), 0 s", "ipmc-asym: sweep: 4/4 row (100 %), 0 s"]
    assert "\r" not in err


def test_quiet_for_short_work_and_when_disabled(monkeypatch, capsys):
    bar = pr.progress(None, "fit", unit="eval")  # the default interval: short work says nothing
    bar.update(3)
    bar.close()
    monkeypatch.setattr(pr, "LINE_INTERVAL_S", 0.0)
    off = pr.progress(10, "fit", enabled=False)
    off.update(10)
    off.close()
    assert capsys.readouterr().err == ""
