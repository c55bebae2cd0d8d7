"""``python -m activeintent.cli``."""

from activeintent.cli import main

main()
