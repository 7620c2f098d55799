"""Round datasets: the experiment folder, the writer, records, checksums, verify, Hub, policies."""
