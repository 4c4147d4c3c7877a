"""Old place of the analyses' runners: each analysis kind is a module of
:mod:`femmech.scene.kinds` holding its reader and runner, and
:data:`femmech.scene.registry.KINDS` lists them. Every public name this module had works
here with a DeprecationWarning naming its new place (docs/architecture.md, "Moved
names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The names this module had, from their new places."""
    from femmech.deprecation import moved

    kinds = "femmech.scene.kinds."
    return moved(__name__, name, {
        "TASKS": "femmech.scene.registry.RUNNERS",
        "matched_full_modes": kinds + "check.matched_full_modes",
        "run_campbell": kinds + "campbell.run",
        "run_chain_sweep": kinds + "chain_sweep.run",
        "run_check": kinds + "check.run",
        "run_drive_event": kinds + "drive_event.run",
        "run_modes": kinds + "modes.run",
        "run_response": kinds + "response.run",
        "run_stability": kinds + "stability.run",
        "run_sweep": kinds + "sweep.run",
        "run_synthesis": kinds + "synthesis.run",
        "summary_section": "femmech.scene.summary.summary_section",
    }, removed={
        "RPM": "an internal factor; use femmech.output.charts.SPEED_UNITS['rpm']",
    })
