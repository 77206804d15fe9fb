"""What a run's results say: metrics, the comparison with the physics input, tables beside
the paper's, figures and ``report.md``."""
