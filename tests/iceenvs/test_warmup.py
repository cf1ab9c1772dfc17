"""``python -m iceenvs.warmup``: every item runs, a failing one is reported."""


def test_warmup_reports_a_failing_item_and_runs_the_others(monkeypatch, capsys):
    from iceenvs import warmup

    ran = []

    def broken():
        raise TypeError("unknown argument n_floes")

    monkeypatch.setattr(warmup, "items", lambda steps: [
        ("first", lambda: ran.append("first")), ("broken", broken),
        ("last", lambda: ran.append("last") or " (note)")])
    monkeypatch.setenv("SEAICE_QUIET", "1")
    assert warmup.main([]) == 1
    assert ran == ["first", "last"]
    out, err = capsys.readouterr()
    assert "[1/3] first:" in out and "[3/3] last:" in out and "(note)" in out
    assert "[2/3] broken: FAILED: TypeError: unknown argument n_floes" in err
    assert "1 failed)" in out
