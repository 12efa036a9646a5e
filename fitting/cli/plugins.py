"""
Plugins
=======

A plugin is a module that registers what it adds when imported: an export
format (:func:`fitting.exports.formats.register_export_format`), a model
kind (:func:`fitting.models.kinds.register_model_kind` with its fit,
:func:`fitting.fits.kinds.register_fit_kind`). ``COATED_PLUGINS`` names
them, separated by commas, each an importable module name or the path of
a ``.py`` file; ``python -m fitting`` and ``python -m service``
import them at their start, before they read a registry, so a plugin's
format or kind is in every list the CLI and the API derive from them.

-   :func:`load_plugins`: import the modules ``COATED_PLUGINS`` names.
"""

from __future__ import annotations

import importlib
import importlib.util
import os
import re
import sys
from pathlib import Path

__all__ = ["PLUGINS_VARIABLE", "load_plugins"]

PLUGINS_VARIABLE = "COATED_PLUGINS"
_MODULE = re.compile(r"[A-Za-z_]\w*(\.[A-Za-z_]\w*)*")


def load_plugins(value: str | None = None) -> list[str]:
    """
    Import each module of ``value`` (comma-separated module names or
    ``.py`` file paths; by default the ``COATED_PLUGINS`` environment
    variable) and return them. A module imported before (a file: by its
    name, the file's stem) is not imported again.

    Raises ``ValueError`` naming ``COATED_PLUGINS`` for an entry that is
    neither a module name nor a ``.py`` path, or a module that cannot be
    imported.
    """
    value = os.environ.get(PLUGINS_VARIABLE, "") if value is None else value
    names = [name.strip() for name in value.split(",") if name.strip()]
    for name in names:
        try:
            if name.endswith(".py"):
                _import_file(Path(name))
            elif _MODULE.fullmatch(name):
                importlib.import_module(name)
            else:
                raise ValueError(
                    f"`{PLUGINS_VARIABLE}` must list module names or .py files separated by commas, got {name!r}"
                )
        except ImportError as error:
            raise ValueError(f"`{PLUGINS_VARIABLE}` names {name!r}, which cannot be imported: {error}") from error
    return names


def _import_file(path: Path) -> None:
    """Import the module of the file ``path`` under its stem's name, unless a module of that name is imported."""
    if not _MODULE.fullmatch(path.stem):
        raise ValueError(f"`{PLUGINS_VARIABLE}`'s file {str(path)!r} must be named as a Python module")
    if path.stem in sys.modules:
        return
    if not path.is_file():
        raise ImportError(f"no file {str(path)!r}")
    spec = importlib.util.spec_from_file_location(path.stem, path)
    if spec is None or spec.loader is None:
        raise ImportError(f"{str(path)!r} is not a Python module")
    module = importlib.util.module_from_spec(spec)
    sys.modules[path.stem] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[path.stem]
        raise
