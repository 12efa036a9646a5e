"""fitting's public names: each loaded on first use from the module that defines it (PEP 562)."""

from __future__ import annotations

import importlib
import json
import subprocess
import sys
from pathlib import Path

import pytest

import fitting

ROOT = Path(__file__).resolve().parents[2]


def test_every_public_name_is_its_module_s_object():
    assert set(fitting._PUBLIC) == set(fitting.__all__) and len(fitting.__all__) == len(set(fitting.__all__))
    for name, module in fitting._PUBLIC.items():
        assert getattr(fitting, name) is getattr(importlib.import_module(f"fitting.{module}"), name), name
    assert set(fitting.__all__) <= set(dir(fitting))


def test_an_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="module 'fitting' has no attribute 'fit_everything'"):
        fitting.fit_everything  # noqa: B018
    with pytest.raises(ImportError, match="cannot import name 'fit_everything'"):
        from fitting import fit_everything  # noqa: F401


@pytest.mark.slow  # starts a process
def test_import_fitting_loads_no_subpackage_and_a_name_loads_its_own():
    probe = (
        "import json, sys; import fitting; before = sorted(m for m in sys.modules if m.startswith('fitting.'));"
        "from fitting import library_material; after = sorted(m for m in sys.modules if m.startswith('fitting.'));"
        "print(json.dumps([before, after]))"
    )
    done = subprocess.run([sys.executable, "-c", probe], cwd=ROOT, capture_output=True, text=True, timeout=60)
    before, after = json.loads(done.stdout)
    assert before == [] and "fitting.optics.library" in after and "fitting.fits.curves" not in after
