"""Typed scenarios: the :class:`Scenario` and its parts, where it was read from and its planner
(:mod:`.scenario`); reading a file of one scenario or of variants (:mod:`.loading`); the shipped
scenarios and loading a scenario by its file or name (:mod:`.shipped`); every check before the
motion, with errors located in the scenario's file (:mod:`.checks`); strict YAML reading with
line, column and field path (:mod:`.yaml_schema`)."""

from drake_traj.scenario.checks import (check_cell_tcp, check_in_cell, check_planned_duration, check_start_torques, preflight)
from drake_traj.scenario.loading import (scenario_variants)
from drake_traj.scenario.scenario import (ControllerGains, Scenario, ScenarioSource, SpeedOverride, default_plant_config, default_simulator_config, locate_in_scenario, make_planner)
from drake_traj.scenario.shipped import (DEFAULT_SCENARIO, ShippedScenario, default_scenario_path, find_scenario, load_scenario, shipped_copy, shipped_directory, shipped_scenarios)
from drake_traj.scenario.yaml_schema import (ScenarioError, checked_document)

__all__ = ['ControllerGains', 'DEFAULT_SCENARIO', 'Scenario', 'ScenarioError', 'ScenarioSource', 'ShippedScenario', 'SpeedOverride', 'check_cell_tcp', 'check_in_cell', 'check_planned_duration', 'check_start_torques', 'checked_document', 'default_plant_config', 'default_scenario_path', 'default_simulator_config', 'find_scenario', 'load_scenario', 'locate_in_scenario', 'make_planner', 'preflight', 'scenario_variants', 'shipped_copy', 'shipped_directory', 'shipped_scenarios']
