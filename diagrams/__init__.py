"""Scenario YAML files shipped as package data (drake_traj.diagrams)."""
