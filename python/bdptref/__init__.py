"""bdptref: the reference renderer's library for test suites (docs/library.md).

Three jobs, with NumPy arrays for images and paths:

* MIS weights of a path: :func:`mis_weights` (a "bdptref-path" dict/JSON/file, scene or densities
  form, as `bdptref mis` reads it) and :func:`mis_weights_densities` (explicit per-vertex densities);
* the calibrated comparison: :func:`compare` (two images: arrays, Images, Films or files) and
  :func:`compare_set` (a set of renders against one reference);
* films: :func:`read_film`, :func:`write_film`, :class:`Film`, and :func:`render` a scene
  (:func:`load_scene`) into a film in-process.

Errors raise :class:`InputError` (a ValueError) with the command line's messages.
`python3 -m bdptref ARGS` runs the `bdptref` command line.
"""
import json as _json
import os as _os
import shutil as _shutil

import numpy as _np

from ._bdptref import (  # noqa: F401  (re-exported API)
    CompareResult,
    Film,
    FilmFile,
    Image,
    InputError,
    RenderSetComparison,
    Scene,
    __version__,
    compare_images,
    git_revision,
    image,
    load_scene,
    mis_weights_densities,
    mis_weights_file,
    mis_weights_json,
    read_film,
    read_image,
    render,
    write_film,
)
from . import _bdptref

__all__ = [
    "CompareResult", "Film", "FilmFile", "Image", "InputError", "RenderSetComparison", "Scene",
    "__version__", "cli_binary", "compare", "compare_set", "image", "load_scene", "mis_weights",
    "mis_weights_densities", "read_film", "read_image", "render", "to_image", "write_film",
]


def _jsonable(x):
    """NumPy arrays and scalars inside a path dict become plain lists and numbers."""
    if isinstance(x, dict):
        return {k: _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, _np.ndarray):
        return _jsonable(x.tolist())
    if isinstance(x, _np.generic):
        return x.item()
    return x


def mis_weights(path, scene="", form="auto", width=0, height=0, heuristic=None, beta=None, s=-1, t=-1, light_sampler=None):
    """MIS weights of every strategy (s = 0..n-1) of a full path, as `bdptref mis` computes them.

    path: a "bdptref-path" dict (docs/trace-and-mis.md; NumPy arrays allowed for "p", "ng", ...),
    its JSON text, or a file name (a "bdptref-trace" file with s, t picking a connection).
    scene: a scene file for the scene form (default: the one the path records).
    heuristic: "balance" | "power" | "uniform" (default: recorded in the path, else balance).
    light_sampler: "power" | "tree", s = 1's light choice (default: recorded in the path, else power;
    docs/mis.md, "Light tree in BDPT").
    Returns a dict: form, weights, valid, s, t, reasons, log_density, sum, heuristic, beta, warnings.
    """
    if isinstance(path, dict):
        return mis_weights_json(_json.dumps(_jsonable(path)), form, scene, width, height, heuristic, beta, light_sampler)
    if isinstance(path, str) and path.lstrip().startswith("{"):
        return mis_weights_json(path, form, scene, width, height, heuristic, beta, light_sampler)
    return mis_weights_file(_os.fspath(path), form, scene, width, height, heuristic, beta, s, t, light_sampler)


def to_image(x, variance=None, count=None):
    """An :class:`Image` from an Image, a Film, a file name, or a (H, W, 3) mean array (with optional
    (H, W, 3) variance of the mean and (H, W) sample count arrays)."""
    if isinstance(x, Image):
        return x
    if isinstance(x, Film):
        return x.image()
    if isinstance(x, (str, _os.PathLike)):
        return read_image(_os.fspath(x))
    return image(_np.asarray(x, dtype=_np.float32), variance, count)


def compare(test, reference, test_variance=None, reference_variance=None, test_count=None, reference_count=None,
            alpha=0.01, epsilon=1e-2, min_effective=10.0, precision=1e-5):
    """The calibrated comparison of `bdptref compare` (docs/compare.md): is `test` consistent with
    `reference` up to Monte Carlo noise? test/reference: arrays (H, W, 3), Images, Films or files.
    Returns a :class:`CompareResult` (truthy when consistent): p_value, flagged_mask, sentence, ..."""
    return compare_images(to_image(test, test_variance, test_count),
                          to_image(reference, reference_variance, reference_count),
                          alpha, epsilon, min_effective, precision)


def compare_set(renders, reference, alpha=0.01, epsilon=1e-2, min_effective=10.0, precision=1e-5):
    """Each render of a set (arrays, Images, Films or files) compared with one reference; the set's
    p-value is the Sidak combination of the smallest one. Returns a :class:`RenderSetComparison`."""
    return _bdptref.compare_set([to_image(r) for r in renders], to_image(reference),
                                alpha, epsilon, min_effective, precision)


def cli_binary():
    """The bdptref command-line binary: installed with this package, else $BDPTREF_BINARY, else PATH."""
    from ._paths import BINDIR_FROM_PACKAGE
    here = _os.path.dirname(_os.path.abspath(__file__))
    for candidate in (_os.path.join(here, BINDIR_FROM_PACKAGE, "bdptref"), _os.environ.get("BDPTREF_BINARY", "")):
        if candidate and _os.access(candidate, _os.X_OK):
            return _os.path.normpath(candidate)
    return _shutil.which("bdptref")
