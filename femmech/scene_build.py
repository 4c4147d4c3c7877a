"""Old path of :mod:`femmech.scene.build` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "Prepared": "femmech.scene.build.Prepared",
        "check_part": "femmech.scene.build.check_part",
        "edges_to_node_sets": "femmech.scene.build.edges_to_node_sets",
        "fail": "femmech.scene.load.fail",
        "finding_lines": "femmech.scene.build.finding_lines",
        "interface": "femmech.scene.build.interface",
        "machine_mounts": "femmech.scene.build.machine_mounts",
        "merged_mesh": "femmech.scene.build.merged_mesh",
        "own_coordinates": "femmech.scene.build.own_coordinates",
        "part_findings": "femmech.scene.build.part_findings",
        "part_mesh": "femmech.scene.build.part_mesh",
        "part_model": "femmech.scene.build.part_model",
        "plain": "femmech.scene.build.plain",
        "prepare": "femmech.scene.build.prepare",
        "reduce_part": "femmech.scene.build.reduce_part",
        "reduction_key_data": "femmech.scene.build.reduction_key_data",
        "sha256_key": "femmech.scene.build.sha256_key",
    })
