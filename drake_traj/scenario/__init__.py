"""Typed scenarios: the :class:`Scenario` and its parts, files of one scenario or of variants,
shipped names, and a scenario's planner and preflight with errors located in its file
(:mod:`.scenario`); strict YAML reading with line, column and field path (:mod:`.yaml_schema`)."""

from drake_traj.scenario.scenario import (ControllerGains, Scenario, ScenarioError, ScenarioSource, ShippedScenario, SpeedOverride, default_plant_config, default_scenario_path, default_simulator_config, find_scenario, load_scenario, check_cell_tcp, check_planned_duration, check_start_torques, locate_in_scenario, make_planner, preflight, scenario_variants, shipped_copy, shipped_scenarios)
from drake_traj.scenario.yaml_schema import (checked_document)

__all__ = ['ControllerGains', 'Scenario', 'ScenarioError', 'ScenarioSource', 'ShippedScenario', 'SpeedOverride', 'check_cell_tcp', 'check_planned_duration', 'check_start_torques', 'checked_document', 'default_plant_config', 'default_scenario_path', 'default_simulator_config', 'find_scenario', 'load_scenario', 'locate_in_scenario', 'make_planner', 'preflight', 'scenario_variants', 'shipped_copy', 'shipped_scenarios']
