"""Old path of :mod:`femmech.output.report` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "CSS": "femmech.output.report.CSS",
        "Figure": "femmech.output.report.Figure",
        "Flagged": "femmech.output.report.Flagged",
        "Section": "femmech.output.report.Section",
        "Table": "femmech.output.report.Table",
        "render_report": "femmech.output.report.render_report",
        "render_section": "femmech.output.report.render_section",
        "render_table": "femmech.output.report.render_table",
        "write_report": "femmech.output.report.write_report",
    })
