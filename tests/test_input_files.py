"""Every reader refuses a folder, a missing, an unreadable or an empty file alike."""

import os

import pytest

from metrosync import ParameterError
from metrosync._input_files import check_input_file
from metrosync.cli import main


def test_a_folder_is_named_as_a_folder_with_some_of_its_files(tmp_path):
    for name in ["b.wav", "a.wav", "c.log", "d.log", "e.nc", ".hidden"]:
        (tmp_path / name).write_text("x")
    with pytest.raises(ParameterError) as caught:
        check_input_file(tmp_path, "recording")
    text = str(caught.value)
    assert f"recording {str(tmp_path)!r} is a directory; give a file" in text
    assert "'a.wav', 'b.wav', 'c.log', 'd.log' and 1 more" in text
    assert ".hidden" not in text


def test_missing_empty_and_unreadable_files_each_say_which(tmp_path):
    with pytest.raises(ParameterError, match="the file does not exist.$"):
        check_input_file(tmp_path / "x.nc", "sweep")
    with pytest.raises(ParameterError, match="nor does the folder"):
        check_input_file(tmp_path / "no" / "x.nc", "sweep")
    empty = tmp_path / "e.log"
    empty.write_text("")
    with pytest.raises(ParameterError, match=r"the file is empty \(0 bytes\)"):
        check_input_file(empty, "light-gate log")
    assert check_input_file(empty, "light-gate log", allow_empty=True) == empty
    if os.geteuid() != 0:  # root reads every file
        locked = tmp_path / "l.wav"
        locked.write_text("x")
        locked.chmod(0)
        with pytest.raises(ParameterError, match="permission denied"):
            check_input_file(locked, "recording")


def test_the_reader_chooses_the_error_class(tmp_path):
    from metrosync.video.reader import VideoFileError

    with pytest.raises(VideoFileError, match="is a directory"):
        check_input_file(tmp_path, "video", error=VideoFileError)


@pytest.mark.parametrize(
    ("argv", "what"),
    [
        (["analyze"], "light-gate log"),
        (["track"], "video"),
        (["critical"], "sweep"),
        (["sweep", "--out", "x.nc"], "grid file"),
    ],
)
def test_each_command_given_a_folder_says_it_is_one(tmp_path, capsys, argv, what):
    (tmp_path / "run.txt").write_text("x")
    argv = [argv[0], str(tmp_path), *argv[1:]]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert f"{what} {str(tmp_path)!r} is a directory; give a file inside it" in err


def test_a_regions_folder_is_named_as_a_folder(tmp_path, capsys):
    (tmp_path / "pivots.txt").write_text("100 200\n")
    assert main(["track", str(tmp_path / "film.mp4"), "--regions", str(tmp_path)]) == 2
    assert f"`regions` (--regions) file {str(tmp_path)!r} is a directory" in capsys.readouterr().err
