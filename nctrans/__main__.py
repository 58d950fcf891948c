"""`python -m nctrans` runs the command line."""
import sys

from nctrans.cli import main

sys.exit(main())
