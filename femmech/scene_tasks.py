"""Old path of :mod:`femmech.scene.tasks` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "TASKS": "femmech.scene.tasks.TASKS",
        "run_check": "femmech.scene.tasks.run_check",
        "run_modes": "femmech.scene.tasks.run_modes",
        "run_response": "femmech.scene.tasks.run_response",
        "run_stability": "femmech.scene.tasks.run_stability",
        "run_sweep": "femmech.scene.tasks.run_sweep",
        "summary_section": "femmech.scene.summary.summary_section",
    }, removed={
        "RPM": "an internal factor; use femmech.output.charts.SPEED_UNITS['rpm']",
    })
