"""Helpers every wing may use: errors, option parsing, quiet libraries, LeRobot compatibility, seeds."""
