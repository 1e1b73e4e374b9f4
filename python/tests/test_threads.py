"""Threads: a Scene shared between threads stays valid and never raises borrow errors; a Drive
used from another thread raises a clear RuntimeError (an Exception, not a PanicException)."""

import threading

import pytest

import hdi_tribology as hdi


def test_a_scene_shared_between_threads(paper_scene):
    scene = hdi.Scene.paper()
    errors = []

    def work(i):
        try:
            for k in range(30):
                scene["voltage.dc_v"] = 0.5 + 0.125 * ((i + k) % 5)
                scene["voltage.dc_v"]
                hdi.Scene.paper() == scene
        except Exception as e:  # noqa: BLE001 - any error fails the test below
            errors.append(e)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    assert scene["voltage.dc_v"] in [0.5 + 0.125 * j for j in range(5)]


def test_a_drive_used_from_another_thread_raises_runtime_error(paper_scene):
    drive = hdi.Drive(paper_scene, flat_disk=True)
    drive.step(60.0)
    caught = []

    def other():
        try:
            drive.step(60.0)
        except Exception as e:  # noqa: BLE001 - it must be an Exception at all
            caught.append(e)

    t = threading.Thread(target=other)
    t.start()
    t.join()
    assert len(caught) == 1 and isinstance(caught[0], RuntimeError), caught
    assert "thread" in str(caught[0])
    # the drive goes on in its own thread
    assert drive.step(60.0).time_s == pytest.approx(100e-6, rel=1e-12)
