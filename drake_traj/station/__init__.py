"""The closed loop: planner -> lookahead -> PD actuators + inverse dynamics -> discrete plant, with
loggers (:mod:`.loop`: add_station, build_station, make_station), advanced until the planner has
finished (:mod:`.run`: run_station), a whole run over typed settings (:mod:`.simulation`: simulate,
RunSettings), and its live view and standalone recording in Meshcat (:mod:`.meshcat`)."""

from drake_traj.station.loop import (Station, add_speed_override, add_station, build_station, make_station)
from drake_traj.station.run import (run_station)
from drake_traj.station.simulation import (RunSettings, simulate)
from drake_traj.station.meshcat import (SPEED_SLIDER, SpeedSlider, TcpTrail, add_live_view, draw_refusal, draw_task, draw_tcp_path, export_html, frame_task, start_meshcat, wait_for_browser)

__all__ = ['RunSettings', 'SPEED_SLIDER', 'SpeedSlider', 'Station', 'TcpTrail', 'add_live_view', 'add_speed_override', 'add_station', 'build_station', 'draw_refusal', 'draw_task', 'draw_tcp_path', 'export_html', 'frame_task', 'make_station', 'run_station', 'simulate', 'start_meshcat', 'wait_for_browser']
