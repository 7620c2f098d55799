"""LeRobot policy plugins (``--policy.discover_packages_path=lerobot_mtdagger.policies``)."""
