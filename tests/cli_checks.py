"""What the command-line tests share."""
from pathlib import Path

import pytest


def assert_refused(main, argv: list[str], words, run_dir: Path, capsys) -> None:
    """``main(argv + ["--out", run_dir])`` exits with status 2, its message
    names every one of ``words``, and ``run_dir`` was not created."""
    with pytest.raises(SystemExit) as exc:
        main([*argv, "--out", str(run_dir)])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    for word in words:
        assert word in err
    assert not run_dir.exists()
