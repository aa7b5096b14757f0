"""What a run leaves on disk: the run folder and its manifest, result files, summaries and
tables, VTK exports, plots, the report and the 3-D view."""
