"""The names of the mooring lines' FtForcePoints files, as DualSPHysics's JDsFtForcePoints names them:
``ft`` the floating's place among all the case's floatings (mkbound order), ``pt`` the fairlead's place
among all the fairleads (the moored floatings in mkbound order, each body's in its lines' order)."""
from sphdvi.io.moorings_out import force_point_files


def _line(body, fixed_first=True):
    ends = [{"kind": "fixed", "body": None}, {"kind": "vessel", "body": body}]
    return {"ends": ends if fixed_first else ends[::-1]}


def test_force_point_files_follow_dualsphysics_numbering():
    # floatings 40 (not moored), 45 and 60 (moored; listed 60 first); lines: 60, 45, 60, 45 (vessel end first)
    lines = [_line(60), _line(45), _line(60), _line(45, fixed_first=False)]
    names = force_point_files(lines, moored=[60, 45], floatings=[60, 40, 45])
    assert names == [("FtForcePoints_ft0001_pt00.csv", 1, 1), ("FtForcePoints_ft0001_pt01.csv", 3, 0),
                     ("FtForcePoints_ft0002_pt02.csv", 0, 1), ("FtForcePoints_ft0002_pt03.csv", 2, 1)]


def test_two_vessel_ends_of_one_line_are_two_points():
    line = {"ends": [{"kind": "vessel", "body": 45}, {"kind": "vessel", "body": 50}]}
    assert force_point_files([line], moored=[45, 50], floatings=[45, 50]) == [
        ("FtForcePoints_ft0000_pt00.csv", 0, 0), ("FtForcePoints_ft0001_pt01.csv", 0, 1)]
