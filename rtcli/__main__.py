"""python -m rtcli: the command line (the guard keeps processes that re-import this module, as
multiprocessing's spawn does for a cluster's workers, from running it)."""

from rtcli.cli import main

if __name__ == "__main__":
    main()
