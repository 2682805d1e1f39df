"""bodies.csv / links.csv cut back to the restart time on resume (io.runfiles.BodyLog)."""
from sphdvi.dvi.runner import BODIES_HEADER, LINKS_HEADER, csv_time
from sphdvi.io.runfiles import BodyLog


def test_resume_keeps_the_row_written_at_the_restart_time(tmp_path):
    """The time column has 9 digits: a restart time whose printed value rounds up must
    still keep its own row (and drop the later ones)."""
    t_restart = 0.1500393946                  # prints as 0.150039395 > t_restart
    assert float(csv_time(t_restart)) > t_restart
    times = [0.1, t_restart, 0.1600393946]
    for name, header in (("bodies.csv", BODIES_HEADER), ("links.csv", LINKS_HEADER)):
        rows = "".join(f"{csv_time(t)},b,1,2\n" for t in times)
        (tmp_path / name).write_text(header + "\n" + rows + "0.17,b,1")   # a torn last line
    BodyLog(str(tmp_path), None, ["b"], resume_time=t_restart)
    for name in ("bodies.csv", "links.csv"):
        lines = (tmp_path / name).read_text().splitlines()
        assert [ln.split(",")[0] for ln in lines[1:]] == [csv_time(0.1), csv_time(t_restart)]
