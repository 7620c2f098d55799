"""The ``Expert`` protocol and the experts of each task suite."""
