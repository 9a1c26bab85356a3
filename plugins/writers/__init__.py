"""Built-in report writers: each writes files of a benchmark's output folder from the run."""
