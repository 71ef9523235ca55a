"""No leak: the resident memory stays flat over 10^4 events with the arrays read at each.

RSS from /proc/self/status (Linux). Tolerance: 8 MiB of growth between the end of the
first run (the allocator warm) and the end of the last, over at least 10^4 events; a
leak of one traction array (980 doubles, 7.7 kB) per event would add about 77 MB."""

import gc
from pathlib import Path

import precursors


def _rss_bytes() -> int:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) * 1024
    raise RuntimeError("no VmRSS in /proc/self/status")


def _one_run(scene: precursors.Scene) -> int:
    events = 0
    driver = scene.driver()
    for event in driver:
        events += 1
        driver.normal_traction
        driver.site_states
        driver.column_contact_area
        if event.index % 50 == 0:
            driver.checkpoint().to_bytes()
    return events


def test_memory_flat_over_ten_thousand_events(calibration):
    _one_run(calibration)  # the allocator warm
    gc.collect()
    start = _rss_bytes()
    events = 0
    while events < 10_000:
        events += _one_run(calibration)
    gc.collect()
    growth = _rss_bytes() - start
    assert events >= 10_000
    assert growth < 8 * 2**20, f"RSS grew by {growth / 2**20:.1f} MiB over {events} events"
