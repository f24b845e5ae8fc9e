"""Output files appear whole or not at all."""

import pytest

from metrosync._files import atomic_path, save_figure, write_text


def test_a_failed_write_keeps_the_old_file_and_leaves_no_temporary(tmp_path):
    path = tmp_path / "sub" / "result.txt"
    write_text("old", path)
    with pytest.raises(RuntimeError), atomic_path(path) as tmp:
        assert tmp.parent == path.parent and tmp.name.startswith(".result.txt.")
        assert not tmp.match("*.txt")  # a glob for the real files never sees it
        tmp.write_text("half")
        raise RuntimeError("crash while writing")
    assert path.read_text() == "old"
    assert [p.name for p in path.parent.iterdir()] == ["result.txt"]
    write_text("new", path)
    assert path.read_text() == "new" and len(list(path.parent.iterdir())) == 1


def test_figures_take_the_format_of_their_suffix(tmp_path):
    from matplotlib.figure import Figure

    fig = Figure()
    fig.subplots().plot([0, 1], [1, 0])
    assert save_figure(fig, tmp_path / "f.pdf").read_bytes().startswith(b"%PDF")
    assert save_figure(fig, tmp_path / "f.svg").read_text().lstrip().startswith("<?xml")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.pdf", "f.svg"]
