"""The cost of an output (audit e, finding 4): VTKHDFParticleWriter.append wrote 28 datasets
through h5py's high-level calls and looked up ~49 groups per output (~6 ms whatever the
particle count); it now keeps the datasets it writes and appends with h5py's low-level calls:
no group look-up per output, the same file (tests/run and tests/cli check reading it during a
run, resuming and cutting an interrupted append)."""
import h5py
import numpy as np

from sphdvi.io.vtkhdf import VTKHDFParticleWriter, read_step, step_times
from sphdvi.simulation import POINT_ARRAYS


def _data(rng, n):
    return rng.random((n, 3)), {k: (rng.random((n,) if c == 1 else (n, c)) * 100).astype(dt)
                                for k, (dt, c) in POINT_ARRAYS.items()}


def test_append_looks_up_no_group(tmp_path, monkeypatch):
    """After the first output (which grows the vertex topology), an append opens no h5py
    group or dataset by name: the writer keeps them."""
    rng = np.random.default_rng(0)
    w = VTKHDFParticleWriter(str(tmp_path / "p.vtkhdf"), POINT_ARRAYS, points_per_step=100)
    w.append(0.0, *_data(rng, 100))
    looked = []
    get = h5py.Group.__getitem__
    monkeypatch.setattr(h5py.Group, "__getitem__", lambda self, name: looked.append(name) or get(self, name))
    for k in range(1, 4):
        w.append(0.1 * k, *_data(rng, 90 + k))
    monkeypatch.undo()
    w.close()
    assert looked == []
    assert np.allclose(step_times(str(tmp_path / "p.vtkhdf")), [0.0, 0.1, 0.2, 0.3])


def test_appended_steps_read_back(tmp_path):
    """Steps of changing sizes, a reopen for appending after an interrupted append (rows past
    NSteps, cut by the next append) and a truncation read back as written."""
    rng = np.random.default_rng(1)
    path = str(tmp_path / "p.vtkhdf")
    written = []
    w = VTKHDFParticleWriter(path, POINT_ARRAYS, points_per_step=50)
    for k, n in enumerate((50, 40, 60)):
        pts, arrs = _data(rng, n)
        w.append(0.1 * k, pts, arrs)
        written.append((pts, arrs))
    w.close()
    w = VTKHDFParticleWriter(path, POINT_ARRAYS, append=True)
    w.truncate_to(2)
    written = written[:2]
    w.root["Points"].resize(w.root["Points"].shape[0] + 7, axis=0)       # an interrupted append
    w.root["NumberOfPoints"].resize(w.root["NumberOfPoints"].shape[0] + 1, axis=0)
    pts, arrs = _data(rng, 70)
    w.append(0.25, pts, arrs)
    written.append((pts, arrs))
    w.close()
    assert np.array_equal(step_times(path), [0.0, 0.1, 0.25])
    for k, (pts, arrs) in enumerate(written):
        got = read_step(path, k)
        assert np.array_equal(got["points"], pts)
        for name, a in arrs.items():
            assert np.array_equal(got[name], a)
    with h5py.File(path, "r") as f:
        root = f["VTKHDF"]
        assert root["Points"].shape[0] == 160 and root["NumberOfPoints"].shape[0] == 3
        assert list(root["Vertices/NumberOfCells"][...]) == [50, 40, 70]
        assert list(root["Steps/PointDataOffsets/Rhop"][...]) == [0, 50, 90]


def test_checkpoint_arrays_as_h5py_writes_them(tmp_path):
    """restart.h5's arrays (io.bodystate.write_array, h5py's low-level calls) are the datasets
    h5py's create_dataset makes: dtype, shape, values, layout, fill and time tracking."""
    from sphdvi.io.bodystate import write_array
    arrays = {"f": np.random.default_rng(2).random((7, 3)), "i": np.arange(5, dtype=np.int32),
              "b": np.array([True, False, True]), "u": np.arange(4, dtype=np.uint8), "empty": np.zeros((0, 3)),
              "scalar": np.float64(2.5), "strided": np.arange(12.0).reshape(3, 4)[:, ::2]}
    with h5py.File(tmp_path / "a.h5", "w") as f:
        for name, a in arrays.items():
            f.create_dataset(name, data=a)
    with h5py.File(tmp_path / "b.h5", "w") as f:
        for name, a in arrays.items():
            write_array(f, name, a)

    def props(ds):
        pl = ds.id.get_create_plist()
        return (ds.dtype, ds.shape, pl.get_layout(), pl.get_fill_time(), pl.get_obj_track_times(), pl.get_nfilters())

    with h5py.File(tmp_path / "a.h5") as a, h5py.File(tmp_path / "b.h5") as b:
        for name in arrays:
            assert props(a[name]) == props(b[name]), name
            assert np.array_equal(a[name][()], b[name][()]), name
