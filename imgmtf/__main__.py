"""``python -m imgmtf``: the ``imgmtf`` command, for an environment whose
scripts folder is not on the PATH.  The guard keeps a worker pool's
processes, which import the main module again, from running the command."""
from .cli import main

if __name__ == "__main__":
    main(prog_name="imgmtf")
