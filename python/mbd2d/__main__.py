"""python -m mbd2d: the command-line interface."""
from .cli import main

raise SystemExit(main())
