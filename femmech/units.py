"""Old path of :mod:`femmech.scene.units` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "ANGLE": "femmech.scene.units.ANGLE",
        "AREA": "femmech.scene.units.AREA",
        "DAMPING": "femmech.scene.units.DAMPING",
        "DENSITY": "femmech.scene.units.DENSITY",
        "DIMENSIONLESS": "femmech.scene.units.DIMENSIONLESS",
        "Dimension": "femmech.scene.units.Dimension",
        "FORCE": "femmech.scene.units.FORCE",
        "FREQUENCY": "femmech.scene.units.FREQUENCY",
        "INERTIA": "femmech.scene.units.INERTIA",
        "INVERSE_TIME": "femmech.scene.units.INVERSE_TIME",
        "KINDS": "femmech.scene.units.KINDS",
        "Kind": "femmech.scene.units.Kind",
        "LENGTH": "femmech.scene.units.LENGTH",
        "MASS": "femmech.scene.units.MASS",
        "MAX_TEXT": "femmech.scene.units.MAX_TEXT",
        "MOMENT": "femmech.scene.units.MOMENT",
        "PRESSURE": "femmech.scene.units.PRESSURE",
        "ROT_DAMPING": "femmech.scene.units.ROT_DAMPING",
        "ROT_STIFFNESS": "femmech.scene.units.ROT_STIFFNESS",
        "SECOND_MOMENT": "femmech.scene.units.SECOND_MOMENT",
        "SPEED": "femmech.scene.units.SPEED",
        "STIFFNESS": "femmech.scene.units.STIFFNESS",
        "TIME": "femmech.scene.units.TIME",
        "UNITS": "femmech.scene.units.UNITS",
        "describe": "femmech.scene.units.describe",
        "parse_unit": "femmech.scene.units.parse_unit",
        "quantity": "femmech.scene.units.quantity",
    })
