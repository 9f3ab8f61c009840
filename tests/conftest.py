"""Settings for the whole test session.

The plan cache of ``symrot derive --emit`` (:mod:`symrot.cli.plan_cache`) is off for every test and
every ``symrot`` subprocess they start (the variable is inherited): a test must compute what it
checks, and must not read or fill the user's ~/.cache. tests/test_plan_cache.py turns it on, in a
temporary directory, where it is the subject.
"""

import os

os.environ["SYMROT_NO_CACHE"] = "1"
