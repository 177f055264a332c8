"""UR10e and robot model files shipped as package data (drake_traj.models)."""
