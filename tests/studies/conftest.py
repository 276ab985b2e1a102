import pytest


@pytest.fixture
def fresh_cache():
    """Empty the per-process plan/flight caches of the studies around a test."""
    from pitotcal.studies.engine import common

    common._flight_cached.cache_clear()
    yield
    common._flight_cached.cache_clear()
