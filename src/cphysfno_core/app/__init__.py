"""The application: the pipeline of a run, studies over seeds and sweeps, the command line."""
