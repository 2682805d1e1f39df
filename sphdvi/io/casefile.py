"""The gencase output: one HDF5 file ``<casename>.h5`` that ``sphdvi run`` reads.

Layout::

    /                      attrs: format="sphdvi-case", layout (LAYOUT; absent in the files of
                           sphdvi 0.1.0 and before, the same layout), version (the sphdvi
                           that wrote it), casename, source_file
    /particles/pos         (N,3) f8     positions [m]
              /vel         (N,3) f8     velocities [m/s]
              /rhop        (N,)  f8     density [kg/m3]
              /mass        (N,)  f8     mass [kg] (per metre of width in 2D)
              /type        (N,)  u1     0 fixed bound, 1 moving bound, 2 floating, 3 fluid
              /mk          (N,)  i4     global mk (mkfluid+1, mkbound+fluidcount+1)
              /idp         (N,)  i8     particle id
    /constants             attrs: dp, h, b, cs0, rhop0, gamma, gravity, massfluid, massbound, is2d, ...
    /parameters            attrs: every <parameters> key (resolved, defaults filled)
    /domain                attrs: posmin, posmax (resolved simulation domain)
    /bodies/<datasets>     one row per floating body: mkbound, mk, begin, count, mass, masspart,
                           center (nb,3), inertia (nb,3,3), translation_dof, rotation_dof,
                           linearvelini, angularvelini
    /normals               (N,3) f8     the mDBC normals the case defines (only when it does):
                                        the vector from each boundary particle to the surface
    /json/<name>           UTF-8 JSON text: links, chrono, motions, materials, material_links,
                           gauges, special, initials, normals, bodies_extra, mkinfo
    /source_xml            the case XML text as read
"""
from __future__ import annotations

import json

import numpy as np

from ..errors import InputError, h5_reason
from .atomic import atomic_path

FORMAT = "sphdvi-case"
LAYOUT = 1        # the layout below; a change that older readers cannot read raises it
PARTICLE_FIELDS = ("pos", "vel", "rhop", "mass", "type", "mk", "idp")
BODY_FIELDS = ("mkbound", "mk", "begin", "count", "mass", "masspart", "center", "inertia",
               "translation_dof", "rotation_dof", "linearvelini", "angularvelini")


def _clean_attr(value):
    if value is None:
        return "none"
    if isinstance(value, (list, tuple)):
        return np.asarray(value, dtype=float)
    if isinstance(value, (bool, np.bool_)):
        return np.int8(value)
    return value


def write_case_h5(path: str, *, casename: str, source_file: str, source_xml: str, version: str,
                  particles: dict, constants: dict, parameters: dict, domain: dict,
                  bodies: list, json_items: dict, normals=None) -> None:
    """Write the case file atomically (see the module docstring for the layout)."""
    import h5py
    with atomic_path(path) as tmp:
        with h5py.File(tmp, "w") as f:
            f.attrs["format"] = FORMAT
            f.attrs["layout"] = LAYOUT
            f.attrs["version"] = version
            f.attrs["casename"] = casename
            f.attrs["source_file"] = source_file
            g = f.create_group("particles")
            for name in PARTICLE_FIELDS:
                g.create_dataset(name, data=particles[name])
            c = f.create_group("constants")
            for k, v in constants.items():
                c.attrs[k] = _clean_attr(v)
            p = f.create_group("parameters")
            for k, v in parameters.items():
                p.attrs[k] = _clean_attr(v)
            d = f.create_group("domain")
            for k, v in domain.items():
                d.attrs[k] = _clean_attr(v)
            b = f.create_group("bodies")
            b.attrs["count"] = len(bodies)
            for name in BODY_FIELDS:
                if bodies:
                    b.create_dataset(name, data=np.asarray([getattr(x, name) for x in bodies]))
            if normals is not None:
                f.create_dataset("normals", data=np.asarray(normals, dtype=np.float64))
            j = f.create_group("json")
            for k, v in json_items.items():
                j.create_dataset(k, data=json.dumps(v, default=_json_default))
            f.create_dataset("source_xml", data=source_xml)


def _json_default(obj):
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (np.floating,)):
        return float(obj)
    if hasattr(obj, "__dict__"):
        return obj.__dict__
    raise TypeError(f"cannot serialise {type(obj).__name__}")


def _attr_value(v):
    if isinstance(v, bytes):
        v = v.decode()
    if isinstance(v, str):
        return None if v == "none" else v
    if isinstance(v, np.ndarray):
        return v.tolist()
    if isinstance(v, np.integer):
        return int(v)
    if isinstance(v, np.floating):
        return float(v)
    return v


def read_case_h5(path: str) -> dict:
    """Read a case file back into plain dicts and numpy arrays.  A file that is not one
    (corrupt, truncated, another format, a missing dataset) is an InputError naming it."""
    import h5py
    try:
        return _read_case_h5(h5py, path)
    except InputError:
        raise
    except (OSError, KeyError, ValueError, TypeError) as exc:
        raise InputError(f"{path} is not a readable sphdvi case file ({h5_reason(exc)}; truncated or corrupt?): "
                         "run 'sphdvi gencase' again") from None


def _version_tuple(text) -> tuple | None:
    """(major, minor) of a version string "M.m.p" (None when it is not one)."""
    parts = str(text).split(".")
    try:
        return int(parts[0]), int(parts[1]) if len(parts) > 1 else 0
    except ValueError:
        return None


def check_layout(path: str, attrs) -> None:
    """A case file this sphdvi can read: its ``layout`` no newer than :data:`LAYOUT`; a file without
    one (sphdvi 0.1.0 and before wrote none) is read when the sphdvi ``version`` that wrote it is
    not newer (0.x: major and minor) than this one."""
    from .._version import __version__
    version = _attr_value(attrs.get("version"))
    again = "run 'sphdvi gencase' again with this sphdvi"
    if "layout" in attrs:
        layout = _attr_value(attrs["layout"])
        if not isinstance(layout, int) or layout < 1:
            raise InputError(f"{path} is not a valid sphdvi case file: its layout attribute is {layout!r}: {again}")
        if layout > LAYOUT:
            raise InputError(f"{path} was written by sphdvi {version} in case-file layout {layout}; this sphdvi "
                             f"({__version__}) reads layouts up to {LAYOUT}: {again} (or update sphdvi)")
        return
    mine, theirs = _version_tuple(__version__), _version_tuple(version)
    if theirs is None:
        raise InputError(f"{path} is not a valid sphdvi case file: its version attribute {version!r} is not a "
                         f"sphdvi version: {again}")
    if theirs > mine:
        raise InputError(f"{path} was written by sphdvi {version}, newer than this sphdvi ({__version__}): its "
                         f"layout may differ: {again} (or update sphdvi)")


def _read_case_h5(h5py, path: str) -> dict:
    with h5py.File(path, "r") as f:
        if f.attrs.get("format") != FORMAT:
            raise InputError(f"{path} is not a sphdvi case file (no format=\"{FORMAT}\" attribute)")
        check_layout(path, f.attrs)
        out = {"casename": _attr_value(f.attrs["casename"]), "version": _attr_value(f.attrs["version"]),
               "source_file": _attr_value(f.attrs["source_file"])}
        out["particles"] = {k: f["particles"][k][...] for k in PARTICLE_FIELDS}
        out["constants"] = {k: _attr_value(v) for k, v in f["constants"].attrs.items()}
        out["parameters"] = {k: _attr_value(v) for k, v in f["parameters"].attrs.items()}
        out["domain"] = {k: _attr_value(v) for k, v in f["domain"].attrs.items()}
        out["bodies"] = {k: f["bodies"][k][...] for k in BODY_FIELDS if k in f["bodies"]}
        out["normals"] = f["normals"][...] if "normals" in f else None
        out["json"] = {k: json.loads(f["json"][k][()].decode() if isinstance(f["json"][k][()], bytes)
                                     else f["json"][k][()]) for k in f["json"]}
        src = f["source_xml"][()]
        out["source_xml"] = src.decode() if isinstance(src, bytes) else src
    for key in ("is2d",):
        if key in out["constants"]:
            out["constants"][key] = bool(out["constants"][key])
    problem = _contents_problem(out)
    if problem:
        raise InputError(f"{path} is not a valid sphdvi case file: {problem}: run 'sphdvi gencase' again")
    return out


def _contents_problem(out: dict) -> str | None:
    """What is wrong in a case file's contents (None when nothing): the particle arrays of one
    length and shape, numeric, finite, types 0-3, ids unique; dp, h and the masses of the
    constants positive; the numeric parameters numbers; one row per body."""
    p = out["particles"]
    n = p["pos"].shape[0] if p["pos"].ndim == 2 else -1
    for name in PARTICLE_FIELDS:
        a = p[name]
        shape = (n, 3) if name in ("pos", "vel") else (n,)
        if a.shape != shape:
            return f"particles/{name} has the shape {a.shape}, expected {shape}"
        if a.dtype.kind not in "fiu":
            return f"particles/{name} holds {a.dtype} values, expected numbers"
        if a.dtype.kind == "f" and not np.isfinite(a).all():
            bad = int(np.flatnonzero(~np.isfinite(a.reshape(n, -1)).all(axis=1))[0])
            return f"particles/{name} of particle {bad} is {a[bad].tolist()}, expected finite numbers"
    if n and not np.isin(p["type"], (0, 1, 2, 3)).all():
        return f"particles/type holds {sorted(set(np.unique(p['type']).tolist()) - {0, 1, 2, 3})}, expected 0-3"
    if np.unique(p["idp"]).size != n:
        return "particles/idp holds the same id twice"
    c = out["constants"]
    for key in ("dp", "h", "rhop0", "massfluid", "massbound"):
        if key in c and not (isinstance(c[key], (int, float)) and 0 < c[key] < np.inf):
            return f"constants/{key} is {c[key]!r}, expected a positive number"
    from ..case.parameters import PARAMETERS
    for key, value in out["parameters"].items():
        spec = PARAMETERS.get(key)
        if spec is None or spec.kind == "str" or value is None:
            continue
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value):
            return f"parameters/{key} is {value!r}, expected a number"
    counts = {np.shape(v)[0] if np.ndim(v) else -1 for v in out["bodies"].values()}
    if len(counts) > 1:
        return "the /bodies datasets have different lengths"
    return None
