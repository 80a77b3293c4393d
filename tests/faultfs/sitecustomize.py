"""Test-only: installs :mod:`faultinject` in a subprocess when ``FIBRIL_TEST_FAULT`` is set."""

import os

if os.environ.get("FIBRIL_TEST_FAULT"):
    import faultinject

    faultinject.install(os.environ["FIBRIL_TEST_FAULT"])
