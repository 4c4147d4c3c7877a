"""Mesh files whose model would change without a word: what read_mesh does not carry is
reported, duplicated numbers are refused, repeated elements are named, numbers and
coordinates that overflow are one-line errors; materials whose matrices would not be
finite are refused naming the field."""

from __future__ import annotations

import warnings

import meshio
import numpy as np
import pytest
from models import cbar_card, deck, grid_card
from numpy.testing import assert_array_equal

import femmech as fm
from femmech.cli import INPUT, OK, main
from femmech.errors import FileFormatError
from femmech.fe import sections

STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0, name="steel")
BAR = fm.BeamProperty(sections.rectangle(0.05, 0.08), STEEL, (0, 1, 0))


def read_quietly(path):
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # numpy overflow: must not happen
        return fm.read_mesh(path)


# --- duplicated numbers: errors ----------------------------------------------------------

def test_two_cbars_with_one_number_are_refused(tmp_path):
    # before: both were kept, 5 elements on 4 spans (first frequency 10.44 -> 12.91 Hz)
    path = deck(tmp_path, cbar_card(4, 1, 2))
    with pytest.raises(FileFormatError, match=r"frame.bdf: element 4 is defined twice"
                       r" \(CBAR line 12 and CBAR line 13;"):
        read_quietly(path)


def test_cquad4_reusing_a_cbar_number_is_refused(tmp_path):
    # Nastran numbers elements across all element cards
    path = deck(tmp_path, "CQUAD4  2       10      1       2       3       4\n")
    with pytest.raises(FileFormatError, match=r"element 2 is defined twice \(CBAR line 10 and"
                       r" CQUAD4 line 13"):
        read_quietly(path)


def test_two_grids_with_one_number_are_refused(tmp_path):
    # before: meshio placed the elements on the second GRID 3, the first was left loose
    grids = "".join(grid_card(i + 1, 0.5 * i) for i in range(5)) + grid_card(3, 7.0)
    with pytest.raises(FileFormatError, match=r"GRID 3 is defined twice \(line 6 and line 9"):
        read_quietly(deck(tmp_path, grids=grids))


def test_element_on_an_undefined_grid_names_element_and_grid(tmp_path):
    path = deck(tmp_path, cbar_card(9, 5, 77))
    with pytest.raises(FileFormatError, match=r"CBAR 9 \(line 13\) lists GRID 77, which the"
                       " file does not define"):
        read_quietly(path)


# --- cards and fields not carried: reported ----------------------------------------------

def test_rbe2_and_conm2_are_reported_by_name_and_count(tmp_path):
    extra = ("RBE2    9       5       123456  4\n"
             "CONM2   10      5               100.0\n"
             "CONM2   11      4               50.0\n"
             "PBAR    1       100     1.0E-3\n")
    with pytest.warns(fm.ModelWarning, match=r"frame.bdf: cards not carried into the model:"
                      r" CONM2 x2, PBAR x1, RBE2 x1 \(") as caught:
        mesh = read_quietly(deck(tmp_path, extra))
    assert len(caught) == 1  # one warning per file
    assert mesh.cells["line"].shape == (4, 2)


def test_large_field_and_lower_case_element_cards_are_reported(tmp_path):
    # meshio reads neither: the elements would vanish without a word
    extra = ("CBAR*   5               1               1               3\n"
             "*       0.              1.              0.\n"
             "cbar,6,1,2,4,0.,1.,0.\n")
    with pytest.warns(fm.ModelWarning, match=r"not carried into the model: CBAR\* x1, cbar x1"):
        mesh = read_quietly(deck(tmp_path, extra))
    assert len(mesh.cells["line"]) == 4


def test_celas1_is_reported(tmp_path):
    # meshio reads it as a vertex cell, which is no element: dropped
    with pytest.warns(fm.ModelWarning, match=r"CELAS1 x1"):
        read_quietly(deck(tmp_path, "CELAS1  20      7       5       1\n"))


def test_grid_ps_becomes_a_node_set_and_is_reported(tmp_path):
    # before: the PS field was ignored, GRID 1 was free
    grids = grid_card(1, 0.0, ps="123456") + grid_card(2, 0.5, ps="321") + "".join(
        grid_card(i + 1, 0.5 * i) for i in range(2, 5))
    with pytest.warns(fm.ModelWarning, match=r"GRID permanent constraints \(field PS\) are not"
                      r" applied: they are the node sets PS123 \(1 GRIDs\), PS123456 \(1"
                      r" GRIDs\)"):
        mesh = read_quietly(deck(tmp_path, grids=grids))
    assert_array_equal(mesh.node_sets["PS123456"], [0])
    assert_array_equal(mesh.node_sets["PS123"], [1])
    model = fm.build_model(mesh, {"PID1": BAR}, supports=[fm.Support("PS123456"),
                                                          fm.Support("PS123", "translations")])
    assert model.n_free == 6 * 5 - 6 - 3


def test_grid_ps_with_other_digits_is_refused(tmp_path):
    grids = grid_card(1, 0.0, ps="17") + "".join(grid_card(i + 1, 0.5 * i) for i in range(1, 5))
    with pytest.raises(FileFormatError, match=r"GRID 1 \(line 4\): PS '17'; expected the"
                       " digits 1-6"):
        read_quietly(deck(tmp_path, grids=grids))


def test_grid_cd_is_reported(tmp_path):
    grids = grid_card(1, 0.0, cd="3") + "".join(grid_card(i + 1, 0.5 * i) for i in range(1, 5))
    with pytest.warns(fm.ModelWarning, match=r"1 GRIDs give a displacement coordinate system"
                      r" \(field CD\)"):
        read_quietly(deck(tmp_path, grids=grids))


def test_include_is_refused(tmp_path):
    with pytest.raises(FileFormatError, match=r"INCLUDE \(line 13\): included files are not"
                       " read"):
        read_quietly(deck(tmp_path, "INCLUDE 'masses.bdf'\n"))


def test_a_deck_of_carried_cards_only_gives_no_warning(tmp_path):
    extra = "SPC1    1       123456  1\nSET1    2       4       5\n"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mesh = fm.read_mesh(deck(tmp_path, extra))
    assert_array_equal(mesh.node_sets["SPC1"], [0])


def test_check_prints_what_the_mesh_file_loses(tmp_path, capsys):
    deck(tmp_path, "SPC1    1       123456  1\nRBE2    9       5       123456  4\n"
         "CONM2   10      5               100.0\n")
    scene = tmp_path / "frame.toml"
    scene.write_text('[materials.steel]\nE = "210 GPa"\nnu = 0.3\nrho = "7850 kg/m^3"\n'
                     '[parts.frame]\nmesh = "frame.bdf"\n[parts.frame.sections.PID1]\n'
                     'section = "circle"\ndiameter = "30 mm"\nmaterial = "steel"\n'
                     'orientation = [0, 1, 0]\n[[parts.frame.supports]]\nnodes = "SPC1"\n'
                     '[analyses.modes]\nn_modes = 3\n')
    assert main(["check", str(scene)]) == OK
    out = capsys.readouterr().out
    assert "frame.toml: warning: " in out
    assert "cards not carried into the model: CONM2 x1, RBE2 x1" in out


# --- repeated elements on the same nodes: warnings ---------------------------------------

PLATE_POINTS = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0], [2, 1, 0]],
                        dtype=float)
PLATE_QUADS = np.array([[0, 1, 2, 3], [1, 4, 5, 2]])


@pytest.mark.parametrize("file_format", ["gmsh", "gmsh22"])
def test_gmsh_repeated_element_is_named_and_dropped(tmp_path, file_format):
    # before: the third quad (a copy of the first, nodes in another order) was kept and
    # doubled the stiffness and mass of the left half of the plate
    quads = np.r_[PLATE_QUADS, [[1, 2, 3, 0]]]
    path = tmp_path / "plate.msh"
    tags = np.array([1, 1, 2])
    meshio.write(path, meshio.Mesh(PLATE_POINTS, [("quad", quads)],
                                   cell_data={"gmsh:physical": [tags],
                                              "gmsh:geometrical": [tags]}),
                 file_format=file_format, binary=False)
    with pytest.warns(fm.ModelWarning, match=r"plate.msh: 1 quad elements repeat the nodes of"
                      r" an earlier one \(indices in the file's order\): 2 \(as 0\); dropped"):
        mesh = read_quietly(path)
    assert_array_equal(mesh.cells["quad"], PLATE_QUADS)
    if file_format == "gmsh22":  # physical groups 1 and 2: the kept quad is in both
        assert_array_equal(mesh.cell_sets["1"]["quad"], [0, 1])
        assert_array_equal(mesh.cell_sets["2"]["quad"], [0])


def test_nastran_repeated_element_is_named_and_kept(tmp_path):
    # two CBARs on GRIDs 1-2 with their own numbers (and properties): Nastran keeps both
    path = deck(tmp_path, cbar_card(7, 2, 1, pid=2))
    with pytest.warns(fm.ModelWarning, match=r"1 line elements repeat the nodes of an earlier"
                      r" one \(numbers\): 7 \(as 1\); kept"):
        mesh = read_quietly(path)
    assert len(mesh.cells["line"]) == 5
    assert_array_equal(mesh.cell_sets["PID2"]["line"], [4])


def test_abaqus_repeated_element_is_named_by_its_number(tmp_path):
    path = tmp_path / "frame.inp"
    path.write_text("*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 2, 0, 0\n*ELEMENT, TYPE=B31,"
                    " ELSET=ALL\n10, 1, 2\n11, 2, 3\n12, 2, 1\n")
    with pytest.warns(fm.ModelWarning, match=r"12 \(as 10\); kept"):
        mesh = read_quietly(path)
    assert len(mesh.cells["line"]) == 3


# --- numbers and coordinates that overflow: one-line errors ------------------------------

@pytest.mark.parametrize(("extra", "match"), [
    ("GRID,99999999999999999999,,3.0,0.,0.\n",
     r"GRID \(line 13\): ID 99999999999999999999 is out of range"),
    ("CBAR,99999999999999999999,1,1,2,0.,1.,0.\n",
     r"CBAR \(line 13\): EID 99999999999999999999 is out of range"),
    ("CBAR,9,1,1,99999999999999999999,0.,1.,0.\n",
     r"CBAR 9 \(line 13\): GRID 99999999999999999999 is out of range"),
    ("SET1,5,1,99999999999999999999\n", r"SET1 \(line 13\): ID 99999999999999999999 is out"),
])
def test_numbers_beyond_int64_are_one_line_errors(tmp_path, extra, match):
    # before: "meshio could not read the file (OverflowError: ...)", and for SET1 an
    # OverflowError from numpy, "internal error" on the command line
    with pytest.raises(FileFormatError, match=match) as caught:
        read_quietly(deck(tmp_path, extra))
    assert "\n" not in str(caught.value)


def test_numbers_beyond_int64_on_the_command_line(tmp_path, capsys):
    deck(tmp_path, "SPC1    1       123456  1\nSET1,5,1,99999999999999999999\n")
    scene = tmp_path / "frame.toml"
    scene.write_text('[materials.steel]\nE = "210 GPa"\nnu = 0.3\nrho = "7850 kg/m^3"\n'
                     '[parts.frame]\nmesh = "frame.bdf"\n[parts.frame.sections.PID1]\n'
                     'section = "circle"\ndiameter = "30 mm"\nmaterial = "steel"\n'
                     'orientation = [0, 1, 0]\n[analyses.modes]\nn_modes = 3\n')
    assert main(["check", str(scene)]) == INPUT
    err = capsys.readouterr().err
    assert "internal error" not in err
    assert "SET1 (line 14): ID 99999999999999999999 is out of range" in err


def test_coordinates_of_1e300_are_refused_naming_the_grid(tmp_path):
    # before: accepted, then numpy overflow warnings and a zero-length element error
    grids = "".join(f"GRID,{i + 1},,{x},0.,0.\n" for i, x in enumerate(
        ["0.", "1e300", "1.", "1.5", "2."]))
    with pytest.raises(FileFormatError, match=r"frame.bdf: GRID 2 has coordinates \[1e\+300,"
                       r" 0.0, 0.0\] beyond ±1e\+30 \(MAX_COORDINATE"):
        read_quietly(deck(tmp_path, grids=grids))


def test_gmsh_coordinates_of_1e300_and_infinite_are_refused(tmp_path):
    path = tmp_path / "plate.msh"
    points = PLATE_POINTS.copy()
    points[4, 0] = 1e300
    meshio.write(path, meshio.Mesh(points, [("quad", PLATE_QUADS)]), file_format="gmsh",
                 binary=False)
    with pytest.raises(FileFormatError, match=r"node 4 has coordinates \[1e\+300"):
        read_quietly(path)
    with pytest.raises(ValueError, match=r"node 3 has non-finite coordinates \[inf"):
        fm.Mesh(np.r_[PLATE_POINTS[:3], [[np.inf, 0, 0]]], {"line": [[0, 1]]})


# --- materials whose matrices would not be finite ----------------------------------------

@pytest.mark.parametrize(("values", "match"), [
    (dict(E=5e-324, nu=0.3, rho=7850.0), r"material 'x': E = 5e-324 is outside"),
    (dict(E=210e9, nu=0.3, rho=1e-300), r"material 'x': rho = 1e-300 is outside"),
    (dict(E=1e300, nu=0.3, rho=7850.0), r"material 'x': E = 1e\+300 is outside"),
    (dict(E=210e9, G=1e-320, rho=7850.0), r"material 'x': G = 1e-320 is outside"),
])
def test_materials_outside_the_normal_floats_are_refused(values, match):
    # before: E = 5e-324 built NaN matrices ("the mass matrix has no positive diagonal
    # entry"), rho = 1e-300 overflowed in the eigenvalues, naming no input
    with pytest.raises(ValueError, match=match):
        fm.Material(**values, name="x")


def test_materials_at_the_ends_of_the_range_solve():
    # a 2 m cantilever of 4 beams: f1 ∝ sqrt(E/ρ), so these frequencies scale exactly
    points = np.c_[np.linspace(0, 2, 5), np.zeros(5), np.zeros(5)]
    mesh = fm.Mesh.from_lines(points, np.c_[np.arange(4), np.arange(1, 5)])
    for material in (fm.Material(E=1e-100, nu=0.3, rho=7850.0),
                     fm.Material(E=210e9, nu=0.3, rho=1e-100),
                     fm.Material(E=210e9, nu=0.3, rho=0.0)):
        prop = fm.BeamProperty(sections.rectangle(0.05, 0.08), material, (0, 1, 0))
        with warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)
            warnings.simplefilter("ignore", fm.ModelWarning)  # unit checks: odd on purpose
            model = fm.build_model(mesh, {"all": prop}, supports=[fm.Support(0)],
                                   masses=[fm.PointMass(4, 1.0)] if not material.rho else ())
            assert np.isfinite(fm.modes(model, 2).freq_hz).all()


def test_abaqus_number_beyond_int64_and_far_node_name_line_and_node(tmp_path):
    path = tmp_path / "frame.inp"
    path.write_text("*NODE\n1, 0, 0, 0\n99999999999999999999, 1, 0, 0\n")
    with pytest.raises(FileFormatError, match=r"frame.inp: line 3: number 99999999999999999999"
                       " is out of range"):  # before: "int too big to convert"
        read_quietly(path)
    path.write_text("*NODE\n1, 0, 0, 0\n7, 1e300, 0, 0\n*ELEMENT, TYPE=B31, ELSET=ALL\n"
                    "10, 1, 7\n")
    with pytest.raises(FileFormatError, match=r"frame.inp: node 7 has coordinates \[1e\+300"):
        read_quietly(path)


def test_grid_ps_in_large_and_free_field(tmp_path):
    # GRID* fields 2-5 on the first line; X3, CD, PS on the continuation line
    grids = ("GRID*   1                               0.0             0.0             *G1\n"
             "*G1     0.0                             123456\n"
             "GRID,2,,0.5,0.,0.,,123456\n") + "".join(grid_card(i + 1, 0.5 * i)
                                                      for i in range(2, 5))
    with pytest.warns(fm.ModelWarning, match=r"node sets PS123456 \(2 GRIDs\)"):
        mesh = read_quietly(deck(tmp_path, grids=grids))
    assert_array_equal(mesh.node_sets["PS123456"], [0, 1])


@pytest.mark.parametrize(("repeats", "n_quads"), [("drop", 2), ("keep", 3)])
def test_from_meshio_repeats(repeats, n_quads):
    from femmech.fe.mesh_io import from_meshio

    raw = meshio.Mesh(PLATE_POINTS, [("quad", np.r_[PLATE_QUADS, PLATE_QUADS[1:]])])
    with pytest.warns(fm.ModelWarning, match=r"1 quad elements repeat .*: 2 \(as 1\); dropped"
                      if repeats == "drop" else r"2 \(as 1\); kept"):
        mesh = from_meshio(raw, repeats=repeats)
    assert len(mesh.cells["quad"]) == n_quads
