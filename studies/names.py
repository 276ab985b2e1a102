"""The studies' names, in the catalog's order: light to import (the command line builds its
parser from them without loading the studies); `studies.catalog.STUDIES` holds the studies."""

STUDY_NAMES = ("sample-size", "maneuvers", "sensitivity", "coverage", "wind", "real-alfa",
               "peers", "legs", "design", "monitor", "budget", "legs-flight", "noise",
               "leak", "coverage-tails", "jets")
