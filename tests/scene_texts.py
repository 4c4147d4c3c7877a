"""Scene texts shared by the tests: a small steel grid frame on its base, with modes.

``frame_scene(...)`` gives the TOML text of a scene with one part ``frame`` (a
``grid_frame`` generator, circular steel sections, the ``base`` node set fixed) and an
``[analyses.modes]`` table; the tests add reductions, mechanisms and other analyses
through ``parts_extra`` and ``after``.
"""

from __future__ import annotations

STEEL = """[materials.steel]
E = "210 GPa"
nu = 0.3
rho = "7850 kg/m^3"
"""

CIRCLE_SECTIONS = """[parts.frame.sections]
beams_x = { section = "circle", diameter = "40 mm", material = "steel" }
beams_y = { section = "circle", diameter = "40 mm", material = "steel" }
columns = { section = "circle", diameter = "50 mm", material = "steel" }
"""

CRAIG_BAMPTON = """[parts.frame.reduction]
method = "craig_bampton"
n_modes = 6
interface = [{ nodes = "top", dofs = "translations" }]
"""


def _toml(value) -> str:
    return "[" + ", ".join(_toml(v) for v in value) + "]" if isinstance(value, list | tuple) \
        else str(value)


def frame_scene(name: str = "frame", *, bays=(1, 1, 1), size=(1.0, 0.6, 0.8),
                subdivisions=None, mesh_line: str | None = None, description: str | None = None,
                parts_extra: str = "", n_modes=3, images=0, vtu: bool = False,
                after: str = "") -> str:
    """The scene text; ``mesh_line`` (e.g. ``'mesh = "frame.msh"'``) replaces the
    generator table; ``n_modes`` and ``images`` may be placeholders the test replaces."""
    head = f'[scene]\nname = "{name}"\n'
    if description is not None:
        head += f'description = "{description}"\n'
    if mesh_line is None:
        source = (f'[parts.frame.generator]\nkind = "grid_frame"\nbays = {_toml(bays)}\n'
                  f"size = {_toml(size)}\n")
        if subdivisions is not None:
            source += f"subdivisions = {subdivisions}\n"
    else:
        source = f"[parts.frame]\n{mesh_line}\n"
    modes = (f"[analyses.modes]\nn_modes = {n_modes}\nimages = {images}\n"
             f"vtu = {'true' if vtu else 'false'}\n")
    blocks = [head, STEEL, source, CIRCLE_SECTIONS, '[[parts.frame.supports]]\nnodes = "base"\n',
              parts_extra, modes, after]
    return "\n" + "\n".join(b for b in blocks if b)
