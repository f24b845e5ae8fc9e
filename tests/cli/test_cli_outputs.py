"""Every output option does one thing with its folder: a missing folder is created, and
a folder that cannot be created or written is refused before any work, naming the option."""

import pytest

from metrosync.cli import main

#: (arguments before the output option, the option, the file name it gets).
OUTPUTS = [
    (["simulate", "--duration", "1"], "--out", "r.nc"),
    (["simulate", "--duration", "1"], "--plot", "r.png"),
    (["simulate", "--duration", "1"], "--lightgate-dir", "logs"),
    (["sweep", "--bpm", "180,190", "--duration", "1"], "--out", "w.nc"),
    (["sweep", "--bpm", "180,190", "--duration", "1", "--out", "{ok}/w.nc"], "--store", "pts"),
    (["critical", "{ok}/missing.nc"], "--out", "c.nc"),
    (["critical", "{ok}/missing.nc"], "--plot", "c.png"),
    (["theory", "--no-cache"], "--out", "t.nc"),
    (["theory", "--no-cache"], "--plot", "t.png"),
    (["analyze", "{ok}/missing.log"], "--out", "a.nc"),
    (["analyze", "{ok}/missing.log"], "--plot", "a.png"),
    (["calibrate", "c-theta", "--log", "{ok}/missing.log"], "--plot", "c.png"),
    (["animate", "--duration", "10"], "--out", "a.gif"),
    (["listen", "--duration", "10"], "--out", "t.wav"),
    (["page", "--duration", "10"], "--out", "p.html"),
    (["playground"], "--out", "p.html"),
    (["record", "/dev/null-port"], "--out", "run.log"),
    (["reproduce", "--quick"], "--out", "results"),
]


@pytest.mark.parametrize(("argv", "option", "name"), OUTPUTS)
def test_an_output_folder_that_cannot_be_made_is_refused_first(tmp_path, capsys, argv, option,
                                                               name):  # fmt: skip
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    target = blocker / "sub" / name  # its folder would have to be made inside a file
    argv = [a.replace("{ok}", str(tmp_path)) for a in argv]
    assert main([*argv, option, str(target)]) == 2
    err = capsys.readouterr().err
    assert f"error: `{option}` {str(target)!r}" in err, err
    assert "is not a directory; choose another path." in err, err


def test_a_missing_output_folder_is_created(tmp_path, capsys):
    out = tmp_path / "new" / "deeper" / "r.nc"
    assert main(["simulate", "--n", "2", "--runs", "1", "--duration", "1", "--out", str(out)]) == 0
    assert out.is_file()
