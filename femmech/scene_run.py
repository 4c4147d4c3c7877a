"""Old path of :mod:`femmech.scene.run` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "DEFAULT": "femmech.scene.run.DEFAULT",
        "LOG": "femmech.scene.run.LOG",
        "NUMERICAL_FAILURES": "femmech.scene.run.NUMERICAL_FAILURES",
        "RunResult": "femmech.scene.run.RunResult",
        "Workshop": "femmech.scene.workshop.Workshop",
        "logged_warnings": "femmech.scene.run.logged_warnings",
        "progress": "femmech.scene.workshop.progress",
        "run_scene": "femmech.scene.run.run_scene",
    }, removed={
        "timings_table": "the report's appendix (femmech.scene.summary) has the timings",
    })
