"""Case files, the risk pipeline, run folders and the ``riskassess`` command line."""
from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("adr-riskassess")
except PackageNotFoundError:  # a source tree on sys.path without the installed metadata
    __version__ = "0+unknown"
