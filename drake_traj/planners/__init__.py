"""Planner systems: one module per published planner, plus the shared base and scaling law."""
