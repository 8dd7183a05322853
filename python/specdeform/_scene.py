"""Deformation scenes: a mesh, its handles, how they move, and the settings the scene asks for."""

from __future__ import annotations

import json
import os
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ._specdeform import InputError, MeshReadInfo, _read_scene


@dataclass(eq=False)
class Scene:
    """What SpectralDeformer and its set_selection() and solve() take, read from scene files.

    Vertex indices are in the mesh's numbering (read_mesh's); `info` maps them back to the file.
    `options` are the scene's settings over the defaults, as SpectralDeformer's keywords:

        d = specdeform.SpectralDeformer(s.V, s.F, s.modes, **s.options)
        d.set_selection(s.handles, s.fixed)
        X = d.solve(s.transforms)
    """

    V: np.ndarray
    F: np.ndarray
    info: MeshReadInfo
    handles: list[np.ndarray]
    fixed: np.ndarray
    transforms: list[np.ndarray]
    modes: int | None = None
    options: dict[str, Any] = field(default_factory=dict)


def read_scene(
    path: str | os.PathLike[str],
    mesh: str | os.PathLike[str] | None = None,
    transforms: str | os.PathLike[str] | None = None,
) -> Scene:
    """Reads a scene (docs/scene.md): a JSON scene, or a .sel or .dmat selection with the .def
    file of its transforms. `mesh` defaults to the mesh a JSON scene names (relative to it).

    Raises OSError for a file that cannot be opened, InputError for a malformed one or for a
    handle group whose vertices the mesh reader all dropped (used by no face); warns
    (UserWarning) when it dropped some of a group's or of the fixed set's.
    """
    path = os.fspath(path)
    if mesh is None:
        mesh = _named_mesh(path)
    fields = _read_scene(path, mesh, transforms)
    for note in fields.pop("notes"):
        warnings.warn(f"{path}: {note}", stacklevel=2)
    return Scene(**fields)


def _named_mesh(path: str) -> str:
    if not path.endswith(".json"):
        raise InputError(f"{path}: a selection file names no mesh; pass mesh=")
    try:
        with open(path, "rb") as file:
            scene = json.load(file)
    except json.JSONDecodeError as e:
        raise InputError(f"{path}: not valid JSON ({e.msg}, line {e.lineno})") from None
    if not isinstance(scene, dict) or not isinstance(scene.get("mesh"), str):
        raise InputError(f"{path}: the scene names no mesh; pass mesh=")
    return os.path.join(os.path.dirname(path), scene["mesh"])
