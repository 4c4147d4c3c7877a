"""The main verbs of the data flow at the top level: ``fm.craig_bampton``, ``fm.couple``,
``fm.sweep``, ``fm.run_scene``, ... are the objects of their home modules, imported on
first use so that ``import femmech`` stays light."""

import importlib
import subprocess
import sys

import pytest

import femmech as fm

HOMES = {
    "craig_bampton": "femmech.reduction.component_modes",
    "guyan": "femmech.reduction.component_modes",
    "rheolinear": "femmech.mechanisms.models",
    "Attachment": "femmech.coupling",
    "Mount": "femmech.coupling",
    "couple": "femmech.coupling",
    "sweep": "femmech.analysis.sweep",
    "speed_study": "femmech.analysis.stability",
    "stability_chart": "femmech.analysis.stability",
    "periodic_steady_state": "femmech.analysis.response",
    "load_scene": "femmech.scene.load",
    "run_scene": "femmech.scene.run",
}
"""Each top-level verb → the module that defines it."""


@pytest.mark.parametrize("name", sorted(HOMES))
def test_top_level_verb_is_the_home_modules_object(name):
    assert getattr(fm, name) is getattr(importlib.import_module(HOMES[name]), name)
    assert name in fm.__all__
    assert name in dir(fm)


def test_import_femmech_imports_no_solver_sympy_or_pyvista():
    """The verbs are lazy: ``import femmech`` (and so every ``femmech`` command's start)
    imports neither the sparse solvers, nor sympy, nor the rendering stack."""
    code = ("import sys, femmech;"
            "print(*sorted(m for m in sys.modules if m in {'scipy.sparse.linalg', 'sympy',"
            " 'pyvista', 'vtk', 'femmech.coupling', 'femmech.scene.run'}))")
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True,
                         text=True).stdout
    assert out.strip() == ""
