"""Mechanisms mounted on a Craig-Bampton superelement at interior (non-interface) nodes.

The reduced basis holds the static response to forces at the interface only; a cam one
node off the interface coupled through the fixed-interface modes alone and was accepted
silently. References: the unreduced coupled machine (frame as FE model) solved at each
angle by :func:`femmech.analysis.reference.compare_coupled` (shift-invert, Sturm-checked).
"""

from __future__ import annotations

import importlib.util
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from femmech.analysis.reference import compare_coupled
from femmech.coupling import Attachment, Mount, couple, frame_row
from femmech.errors import InputError
from femmech.reduction import craig_bampton
from femmech.reduction.substructures import assemble_parts

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "textile_shaft.py"
PHI = np.deg2rad([0.0, 45.0])


@cache
def _shaft():
    """(model, superelement, cam mechanism, cam nodes, guide nodes): the textile shaft with
    4 cams, interface = the cams' rx and the guides' uz, f_max 400 Hz."""
    spec = importlib.util.spec_from_file_location("textile_shaft_interior", EXAMPLE)
    ex = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ex)
    model, cams, guides = ex.frame_and_shaft(4, 4)
    se = craig_bampton(model, [(cams, ["rx"]), (guides, ["uz"])], f_max_hz=400.0)
    return model, se, ex.rheolinear(ex.cam_mechanism(), ex.PARAMS, {"U": ex.CAM}), cams, guides


def _cam(node, guide, stiffness=None):
    model, se, mech, cams, guides = _shaft()
    return Mount(mech, (Attachment("q_s", node, "rx", stiffness), Attachment("y_g", guide, "uz")),
                 name="cam")


@pytest.mark.parametrize("stiffness", [None, 1e8])  # rigid and elastic attachment
@pytest.mark.parametrize("form", ["primal", "multiplier"])
def test_a_mount_at_an_interior_node_is_refused(stiffness, form):
    model, se, _, cams, guides = _shaft()
    inner = int(cams[0]) + 1  # a shaft node between two cams: interior
    with pytest.raises(InputError) as info:
        couple(se, [_cam(inner, int(guides[0]), stiffness)], form=form)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"cam: attachment of 'q_s' at node {inner} rx is interior to"
                              " the superelement")
    assert f"craig_bampton(model, interface=[..., ({inner}, ['rx'])])" in message
    assert f'{{ nodes = {inner}, dofs = ["rx"] }} in [parts.<part>.reduction] interface' \
        in message


def test_a_mount_in_a_component_outside_the_interface_is_refused():
    """The cam node is on the interface with rx only: a guide attached there in uz moves
    interior DOFs."""
    _, se, _, cams, _ = _shaft()
    with pytest.raises(InputError, match=rf"'y_g' at node {int(cams[0])} uz is interior"):
        couple(se, [_cam(int(cams[0]), int(cams[0]))])


def test_interface_mounts_are_accurate_and_interior_ones_are_not():
    """At the interface node the reduced coupled quasi-frequencies agree with the
    unreduced machine (measured 6e-13); allow_interior=True couples the interior node and
    is measurably off (6.6e-5): the error the refusal prevents."""
    model, se, _, cams, guides = _shaft()
    errors = {}
    for where, node in (("interface", int(cams[0])), ("interior", int(cams[0]) + 1)):
        mounts = [_cam(node, int(guides[0]))]
        reduced = couple(se, mounts, allow_interior=where == "interior")
        errors[where] = np.abs(compare_coupled(reduced, couple(model, mounts), PHI,
                                               6).rel_error).max()
    # the interface case: residual vectors and f_max 400 Hz make the lowest quasi-modes
    # exact to the solvers' round-off; 1e-8 leaves four decades of margin
    assert errors["interface"] < 1e-8
    assert errors["interior"] > 1e-6


def test_an_interior_node_stays_observable():
    """Output at an interior node (recovery through Ψ and Φ) is not a mount: frame_row
    still gives its row, with modal entries."""
    _, se, _, cams, _ = _shaft()
    row = frame_row(se, int(cams[0]) + 1, "rx")
    assert np.any(row[se.n_interface:])


def test_an_assembly_part_is_checked():
    """On an Assembly of superelements the part's interior is refused too."""
    _, se, _, cams, guides = _shaft()
    assembly = assemble_parts([se])
    inner = Mount(_shaft()[2], (Attachment("q_s", (0, int(cams[0]) + 1), "rx"),
                                Attachment("y_g", (0, int(guides[0])), "uz")), name="cam")
    with pytest.raises(InputError, match=rf"at node {int(cams[0]) + 1} rx of part 0 is"):
        couple(assembly, [inner])
