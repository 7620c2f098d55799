"""The students: ``mtdagger`` and LeRobot's policies, each a ``runner.student.Student`` found by name."""
