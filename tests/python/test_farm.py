"""A render farm from Python: `render(..., sample_range=...)` gives a render state, `merge`
adds states of disjoint sample ranges, and the merged image is the single render's, bit for
bit; the states are the command line's `--sample-range` states, byte for byte."""

import pickle
import subprocess

import numpy as np
import pytest

import prism_renderer as pr
from conftest import SIZE
from test_load import assert_same_image

SPP, SEED = 6, 3


@pytest.fixture(scope="module")
def scene(cornell_path):
    return pr.load_file(cornell_path, resx=SIZE["resx"], resy=SIZE["resy"])


def _part(scene, start, end, **keywords):
    return pr.render(scene, spp=SPP, seed=SEED, sample_range=(start, end), progress=False,
                     **keywords)


def test_merged_ranges_are_the_single_render(scene):
    whole = pr.render(scene, spp=SPP, seed=SEED, progress=False)
    parts = [_part(scene, 2, 5), _part(scene, 0, 2), _part(scene, 5, 6)]
    assert [part.ranges for part in parts] == [[(2, 5)], [(0, 2)], [(5, 6)]]
    merged = pr.merge(parts)
    assert (merged.ranges, merged.spp, merged.seed) == ([(0, 6)], SPP, SEED)
    image = merged.image()
    assert (image.spp, image.seed) == (SPP, SEED)
    assert_same_image(image, whole)
    # In stages, in another order: merging is exact.
    staged = pr.merge([parts[2], pr.merge([parts[0], parts[1]])])
    assert staged.to_bytes() == merged.to_bytes()
    # One range alone is a render of fewer samples, not the whole one.
    assert not np.array_equal(parts[1].image().xyz, whole.xyz)


def test_a_state_pickles_and_is_the_command_lines_file(scene, cornell_path, prism_cli, tmp_path):
    part = _part(scene, 0, 2)
    assert pickle.loads(pickle.dumps(part)).to_bytes() == part.to_bytes()
    cli_state = tmp_path / "cli.state"
    subprocess.run(
        [str(prism_cli), "render", str(cornell_path), "-o", str(tmp_path / "cli.exr"), "-q",
         "--seed", str(SEED), "--spp", str(SPP), "-D", f"resx={SIZE['resx']}",
         "-D", f"resy={SIZE['resy']}", "--sample-range", "0..2", "--checkpoint", str(cli_state)],
        check=True,
        capture_output=True,
    )
    assert part.to_bytes() == cli_state.read_bytes()
    # merge takes files too, and `prism merge` takes the files Python writes.
    rest = tmp_path / "rest.state"
    _part(scene, 2, SPP).write(rest)
    merged = pr.merge([cli_state, str(rest)])
    assert merged.ranges == [(0, SPP)]
    assert pr.RenderState.read(rest).ranges == [(2, SPP)]
    subprocess.run(
        [str(prism_cli), "merge", str(cli_state), str(rest), "-o", str(tmp_path / "m.exr")],
        check=True,
        capture_output=True,
    )
    assert_same_image(merged.image(), pr.Image.read(tmp_path / "m.exr"))


def test_a_range_with_a_checkpoint_resumes_as_the_command_line(scene, tmp_path):
    checkpoint = tmp_path / "part.state"
    first = _part(scene, 1, 3, checkpoint=checkpoint)
    assert checkpoint.read_bytes() == first.to_bytes()
    # Resuming a range continues it from where its state ends.
    longer = _part(scene, 1, 5, resume=checkpoint)
    assert longer.ranges == [(1, 5)]
    assert longer.to_bytes() == _part(scene, 1, 5).to_bytes()


def test_states_that_do_not_merge_are_refused(scene):
    a, b = _part(scene, 0, 3), _part(scene, 2, 4)
    with pytest.raises(pr.PrismError, match="overlap"):
        pr.merge([a, b])
    other_seed = pr.render(scene, spp=SPP, seed=SEED + 1, sample_range=(3, 4), progress=False)
    with pytest.raises(pr.PrismError, match="seed"):
        pr.merge([a, other_seed])
    with pytest.raises(pr.PrismError, match="nothing to merge"):
        pr.merge([])
    with pytest.raises(pr.PrismError, match="empty"):
        _part(scene, 3, 3)
    with pytest.raises(pr.PrismError, match="not a valid render state"):
        pr.RenderState.from_bytes(a.to_bytes()[:-1])


def test_a_cropped_farm_merges_to_the_cropped_render(scene):
    crop = (3, 2, 17, 11)
    whole = pr.render(scene, spp=SPP, seed=SEED, crop=crop, progress=False)
    parts = [_part(scene, 0, 4, crop=crop), _part(scene, 4, SPP, crop=crop)]
    image = pr.merge(parts).image()
    assert (image.width, image.height) == (14, 9)
    assert_same_image(image, whole)
    # A part of the whole film does not merge with a part of the crop.
    with pytest.raises(pr.PrismError, match="crop"):
        pr.merge([parts[0], _part(scene, 4, SPP)])
