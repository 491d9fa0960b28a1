"""The render runs without the GIL, from any thread, and Ctrl-C stops it cleanly."""

import os
import signal
import threading
import time

import pytest

import prism_renderer as pr


def os_threads() -> int:
    return len(os.listdir("/proc/self/task"))


@pytest.fixture(scope="module")
def slow_scene(cornell_path) -> pr.Scene:
    return pr.load_file(cornell_path, spp=4, resx=64, resy=64)


def test_ctrl_c_raises_keyboard_interrupt_and_leaves_no_thread(slow_scene):
    threads_before = os_threads()
    # Ctrl-C is pressed every half second until the render gives up; the first press raises and
    # the later ones are ignored, so that none lands in the test's own code.
    presses = []

    def on_ctrl_c(signum, frame):
        if not presses:
            presses.append(time.monotonic())
            raise KeyboardInterrupt

    stop_pressing = threading.Event()

    def press_ctrl_c():
        while not stop_pressing.wait(0.5):
            os.kill(os.getpid(), signal.SIGINT)

    previous = signal.signal(signal.SIGINT, on_ctrl_c)
    presser = threading.Thread(target=press_ctrl_c)
    start = time.monotonic()
    presser.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            pr.render(slow_scene, time_limit=120, threads=2, progress=False)
    finally:
        stop_pressing.set()
        presser.join()
        signal.signal(signal.SIGINT, previous)
    assert time.monotonic() - start < 30
    # The worker threads are joined before the exception; rayon's pool threads exit soon after.
    deadline = time.monotonic() + 10
    while os_threads() > threads_before and time.monotonic() < deadline:
        time.sleep(0.05)
    assert os_threads() <= threads_before
    # The module still renders afterwards.
    assert pr.render(slow_scene, spp=1, progress=False).spp == 1


def test_other_python_threads_run_while_rendering(slow_scene):
    counts = []
    stop = threading.Event()

    def count():
        n = 0
        while not stop.is_set():
            n += 1
            if n % 1000 == 0:
                counts.append(time.monotonic())

    worker = threading.Thread(target=count)
    worker.start()
    try:
        start = time.monotonic()
        pr.render(slow_scene, time_limit=1.0, progress=False)
        end = time.monotonic()
    finally:
        stop.set()
        worker.join()
    during = [t for t in counts if start < t < end]
    # A thread held off by the GIL for the whole render would count nothing in it.
    assert len(during) > 100


def test_a_render_from_another_thread_gives_the_same_image(slow_scene):
    results = {}

    def run():
        results["image"] = pr.render(slow_scene, spp=1, seed=4, progress=False)

    worker = threading.Thread(target=run)
    worker.start()
    worker.join()
    here = pr.render(slow_scene, spp=1, seed=4, progress=False)
    assert (results["image"].xyz == here.xyz).all()
