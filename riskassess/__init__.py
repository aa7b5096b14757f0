"""Case files, the risk pipeline, run folders and the ``riskassess`` command line."""
