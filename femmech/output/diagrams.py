"""Old path of the stability charts, sweep and history plots, now in
:mod:`femmech.output.stability_charts`, :mod:`femmech.output.sweeps` and
:mod:`femmech.output.histories` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "chart_legend": "femmech.output.stability_charts.chart_legend",
        "plot_mac": "femmech.output.sweeps.plot_mac",
        "plot_orbit": "femmech.output.histories.plot_orbit",
        "plot_speed_study": "femmech.output.stability_charts.plot_speed_study",
        "plot_stability_chart": "femmech.output.stability_charts.plot_stability_chart",
        "plot_time_histories": "femmech.output.histories.plot_time_histories",
        "stability_figure": "femmech.output.stability_charts.stability_figure",
        "write_history_csv": "femmech.output.histories.write_history_csv",
        "write_sweep_csv": "femmech.output.sweeps.write_sweep_csv",
        "write_sweep_json": "femmech.output.sweeps.write_sweep_json",
    })
