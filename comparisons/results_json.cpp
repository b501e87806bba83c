// JSON output of results (filled in by the harness).
