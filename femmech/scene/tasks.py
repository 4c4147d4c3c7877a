"""Old place of the analyses' runners: each analysis kind is a module of
:mod:`femmech.scene.kinds` holding its reader and runner, and
:data:`femmech.scene.registry.KINDS` lists them. Every public name this module had works
here with a DeprecationWarning naming its new place (docs/architecture.md, "Moved
names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The names this module had, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "TASKS": "femmech.scene.registry.RUNNERS",
        "matched_full_modes": "femmech.scene.kinds.check.matched_full_modes",
        "run_campbell": "femmech.scene.kinds.campbell.run",
        "run_chain_sweep": "femmech.scene.kinds.chain_sweep.run",
        "run_check": "femmech.scene.kinds.check.run",
        "run_drive_event": "femmech.scene.kinds.drive_event.run",
        "run_modes": "femmech.scene.kinds.modes.run",
        "run_response": "femmech.scene.kinds.response.run",
        "run_stability": "femmech.scene.kinds.stability.run",
        "run_sweep": "femmech.scene.kinds.sweep.run",
        "run_synthesis": "femmech.scene.kinds.synthesis.run",
        "summary_section": "femmech.scene.summary.summary_section",
    }, removed={
        "RPM": "an internal factor; use femmech.output.charts.SPEED_UNITS['rpm']",
    })
