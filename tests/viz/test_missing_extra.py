"""Without rerun-sdk (the ``viz`` extra) the view, the recording and the replay fail with
one clear line naming the extra; the rest of the command line keeps working."""

from __future__ import annotations

import sys

import pytest

from softarm.cli import main
from softarm.errors import MissingDependencyError, SoftarmError
from softarm.viz.rerun_sdk import require_rerun


@pytest.fixture
def no_rerun(monkeypatch: pytest.MonkeyPatch) -> None:
    # A None entry makes `import rerun` raise ModuleNotFoundError, as when not installed.
    monkeypatch.setitem(sys.modules, "rerun", None)


def test_require_rerun_names_the_extra(no_rerun: None) -> None:
    with pytest.raises(MissingDependencyError, match=r"softarm\[viz\]") as info:
        require_rerun()
    assert isinstance(info.value, SoftarmError) and isinstance(info.value, ImportError)
    assert info.value.extra == "viz"


def test_replay_without_rerun_is_one_line_and_exit_2(no_rerun: None, tmp_path, capsys) -> None:
    log = tmp_path / "run.jsonl"
    log.write_text('{"kind": "transition", "t": 0.0, "old": "idle", "new": "idle"}\n')
    assert main(["replay", str(log), "--record", str(tmp_path / "out.rrd")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("softarm replay: error:") and "softarm[viz]" in err
    assert "\n" not in err and not (tmp_path / "out.rrd").exists()


def test_harvest_record_without_rerun_is_exit_2(no_rerun: None, tmp_path, capsys) -> None:
    out = tmp_path / "run.rrd"
    code = main(["harvest", "--sim", "--berries", "1", "-q", "--record", str(out)])
    assert code == 2
    assert "softarm[viz]" in capsys.readouterr().err and not out.exists()


def test_view_and_record_need_sim(tmp_path, capsys) -> None:
    (tmp_path / "hw.toml").write_text("")
    cfg = str(tmp_path / "hw.toml")
    assert main(["harvest", "--config", cfg, "--record", str(tmp_path / "r.rrd")]) == 2
    assert main(["harvest", "--config", cfg, "--view"]) == 2
    assert "--sim only" in capsys.readouterr().err
