"""Outputs written atomically (temporary file + rename) or appended by rows get the
permissions of a plain open(): 0666 less the umask, not mkstemp's private 0600, so that
the users of a shared project folder can read a run's files."""
import os
import stat

from sphdvi.io.atomic import append_text, atomic_path, write_text_atomic


def mode(path):
    return stat.S_IMODE(os.stat(path).st_mode)


def test_atomic_and_appended_files_follow_the_umask(tmp_path):
    umask = os.umask(0)
    os.umask(umask)
    a, b, c = tmp_path / "run.json", tmp_path / "run.csv", tmp_path / "restart.h5"
    write_text_atomic(str(a), "{}\n")
    append_text(str(b), "1,2\n")
    with atomic_path(str(c)) as tmp:
        with open(tmp, "wb") as fh:
            fh.write(b"x")
    for p in (a, b, c):
        assert mode(p) == 0o666 & ~umask, (p, oct(mode(p)))
    write_text_atomic(str(a), "{\"k\": 1}\n")            # replacing keeps the same mode
    assert mode(a) == 0o666 & ~umask and a.read_text() == "{\"k\": 1}\n"
    assert not [n for n in os.listdir(tmp_path) if n.endswith(".tmp")]



def test_leftover_temporaries_are_removed(tmp_path):
    """A SIGKILL between mkstemp and the rename leaves .NAME.XXXXXXXX.tmp: it goes, the rest stays."""
    from sphdvi.io.atomic import remove_leftover_temporaries
    (tmp_path / ".restart.h5.k3j_x9a1.tmp").write_bytes(b"half a checkpoint")
    (tmp_path / ".notes.tmp").write_text("the user's")
    (tmp_path / ".my.backup.tmp").write_text("the user's (went before: any .X.Y.tmp was taken for one)")
    (tmp_path / "run.csv").write_text("x")
    assert remove_leftover_temporaries(str(tmp_path)) == [".restart.h5.k3j_x9a1.tmp"]
    assert sorted(p.name for p in tmp_path.iterdir()) == [".my.backup.tmp", ".notes.tmp", "run.csv"]
    # what atomic_path makes is what it removes
    import os
    import tempfile
    fd, made = tempfile.mkstemp(prefix=".run.json.", suffix=".tmp", dir=tmp_path)
    os.close(fd)
    assert remove_leftover_temporaries(str(tmp_path)) == [os.path.basename(made)]
