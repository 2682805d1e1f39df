"""The gencase output: one HDF5 file ``<casename>.h5`` that ``sphdvi run`` reads.

Layout::

    /                      attrs: format="sphdvi-case", version, casename, source_file
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


def _read_case_h5(h5py, path: str) -> dict:
    with h5py.File(path, "r") as f:
        if f.attrs.get("format") != FORMAT:
            raise InputError(f"{path} is not a sphdvi case file (no format=\"{FORMAT}\" attribute)")
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
    return out
