"""Identified model parameters stored with the library (thesis Sec 4.4 → later chapters).

The thesis identifies the 39 contact parameters and the 25 body/joint parameters of its child
model once (Ch 4, Sec 4.4, "the third approach") and uses them, fixed, in every later
simulation. The book does the same on its own data: the Ch 4 study
(:mod:`gaitlib.studies.contact_id`) writes its identified values of approach (c) to
``data/identified/ch4_child.json``; a :class:`gaitlib.problems.gait.GaitSpec` with
``contact_params="ch4"`` / ``body_params="ch4"`` reads them through :func:`load_identified`.

File format (JSON, SI units)
----------------------------
``{"name": …, "p_contact": {name: value}, "p_body": {name: value},
"units": {"p_contact": {name: unit}, "p_body": {name: unit}},
"bounds": {"p_contact": {name: [lo, hi]}, "p_body": {name: [lo, hi]}},
"provenance": {…}}`` — the 39 contact parameters in the order of
:func:`gaitlib.contact.param_names` (left foot: N/m³, s/m, –, –, m, m, m, m, m, m, rad,
rad, rad per ellipsoid) and the 25 body/joint parameters of
:data:`gaitlib.model.P_BODY_NAMES` (kg, kg·m², m, N·m/rad, N·m·s/rad). Provenance records the
spec that produced them, the gaitlib version, the cache fingerprint of the code, IPOPT's
status and iterations, the date.

There is no fallback: a missing or malformed file is an error naming the file.
"""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path

import numpy as np

from . import data as data_mod
from . import contact
from .model import P_BODY_NAMES
from .model import ChildModel

__all__ = ["IDENTIFIED_DIR", "identified_path", "load_identified", "contact_params", "body_params"]

#: Where identified parameter sets live (``data/identified/<name>.json``).
IDENTIFIED_DIR = Path(data_mod.DATA_DIR) / "identified"


def identified_path(name: str = "ch4_child") -> Path:
    """Path of the identified parameter set ``name`` (``data/identified/<name>.json``)."""
    return IDENTIFIED_DIR / f"{name}.json"


def _vector(d: dict, names, what: str, path: Path) -> np.ndarray:
    missing = [n for n in names if n not in d]
    extra = [n for n in d if n not in names]
    if missing or extra:
        raise ValueError(f"{path}: {what} has missing {missing} / unknown {extra} entries")
    v = np.array([float(d[n]) for n in names], dtype=float)
    if not np.all(np.isfinite(v)):
        raise ValueError(f"{path}: {what} has non-finite values")
    return v


@lru_cache(maxsize=8)
def _load(path_str: str, mtime_ns: int) -> dict:
    path = Path(path_str)
    try:
        raw = json.loads(path.read_text())
    except json.JSONDecodeError as e:
        raise ValueError(f"{path}: not valid JSON ({e})") from None
    for key in ("p_contact", "p_body", "provenance"):
        if key not in raw:
            raise ValueError(f"{path}: no {key!r} entry")
    return {
        "p_contact": _vector(raw["p_contact"], contact.param_names(), "p_contact", path),
        "p_body": _vector(raw["p_body"], list(P_BODY_NAMES), "p_body", path),
        "provenance": raw["provenance"],
        "bounds": raw.get("bounds", {}),
        "leg_scale": float(raw.get("leg_scale", 1.0)),
        "path": path,
    }


def load_identified(name: str = "ch4_child") -> dict:
    """Load an identified parameter set.

    Parameters
    ----------
    name : str
        File stem under ``data/identified/`` (default ``"ch4_child"``: the Ch 4 approach (c)
        identification on the Free-speed data).

    Returns
    -------
    dict
        ``p_contact`` (39,) SI, ``p_body`` (25,) SI, ``provenance`` (dict), ``bounds``
        (dict of name → [lo, hi]), ``leg_scale`` (the thigh and shank scale of the model it
        was identified on, :attr:`gaitlib.model.ChildModel.leg_scale`; 1 when absent) and
        ``path``. Arrays are fresh copies.

    Raises
    ------
    FileNotFoundError
        The file does not exist (message names it and how it is made).
    ValueError
        The file is not valid JSON or lacks parameters.
    """
    path = identified_path(name)
    if not path.is_file():
        raise FileNotFoundError(
            f"identified parameters {path} not found: it is written by "
            f"gaitlib.studies.contact_id.save_identified (the Ch 4 approach (c) identification)")
    out = _load(str(path), path.stat().st_mtime_ns)
    return {**out, "p_contact": out["p_contact"].copy(), "p_body": out["p_body"].copy()}


#: Named identified sets a spec may read (``GaitSpec.contact_params`` / ``body_params``
#: value → file stem under ``data/identified/``): ``"ch4"`` — Ch 4 approach (c) on the
#: thesis's legs; ``"ch4_legs"`` — the same on thigh and shank ×
#: :data:`gaitlib.studies.gait.LEG_SCALE` (:func:`gaitlib.studies.contact_id.leg_identification`).
IDENTIFIED_SETS = {"ch4": "ch4_child", "ch4_legs": "ch4_legs"}


def contact_params(which: str = "default") -> np.ndarray:
    """The 39 contact parameters (SI, left foot): ``"default"`` — the thesis's identified
    values (Tables 4.17–4.18, :func:`gaitlib.contact.default_params`); ``"ch4"`` — ours
    (approach (c) of Ch 4, :func:`load_identified`); ``"ch4_legs"`` — ours on longer legs
    (:data:`IDENTIFIED_SETS`)."""
    if which == "default":
        return contact.default_params()
    if which in IDENTIFIED_SETS:
        return load_identified(IDENTIFIED_SETS[which])["p_contact"]
    raise ValueError(f"contact parameters must be 'default' or one of {list(IDENTIFIED_SETS)}, got {which!r}")


def body_params(which: str = "default", model=None) -> np.ndarray:
    """The 25 body/joint parameters (SI): ``"default"`` — Tables 4.1–4.3 scaled (Sec 4.1.1);
    ``"thesis"`` — the thesis's identified values (Tables 4.15–4.16); ``"ch4"`` — ours
    (approach (c) of Ch 4, :func:`load_identified`); ``"ch4_legs"`` — ours on longer legs
    (:data:`IDENTIFIED_SETS`). The thigh's and shank's COM distances and inertias follow
    ``model.leg_scale`` from the legs the set was identified on
    (:meth:`~gaitlib.model.ChildModel.leg_scaled`)."""
    model = ChildModel() if model is None else model
    if which == "default":
        return model.default_p_body()
    if which == "thesis":
        return model.leg_scaled(model.p_body_identified())
    if which in IDENTIFIED_SETS:
        s = load_identified(IDENTIFIED_SETS[which])
        return model.leg_scaled(s["p_body"], s["leg_scale"])
    raise ValueError(f"body parameters must be 'default', 'thesis' or one of {list(IDENTIFIED_SETS)}, got {which!r}")
