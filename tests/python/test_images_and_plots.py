"""Grid reduction (area averaging), the palette PNG writer, and the heat-map colour bar."""
import matplotlib.image as mpimg
import numpy as np

import fake_runs
from sdf_report import images, plots


def test_area_averaging_keeps_means_and_constant_images():
    x = np.arange(12, dtype=float).reshape(1, 12, 1)
    half = images.reduce_width(np.repeat(x, 2, axis=0), 6)
    assert half.shape == (1, 6, 1)
    np.testing.assert_allclose(half[0, :, 0], [0.5, 2.5, 4.5, 6.5, 8.5, 10.5], atol=1e-12)
    third = images._area_average(np.arange(7, dtype=float)[:, None], 3, 0)  # fractional cells
    np.testing.assert_allclose(third[:, 0], [(0 + 1 + 1 / 3 * 2) / (7 / 3), (2 / 3 * 2 + 3 + 2 / 3 * 4) / (7 / 3),
                                             (1 / 3 * 4 + 5 + 6) / (7 / 3)], atol=1e-12)
    flat = np.full((10, 30, 3), 0.25)
    np.testing.assert_allclose(images.reduce_width(flat, 7), 0.25, atol=1e-12)
    assert images.reduce_width(flat, 40) is flat  # never enlarged


def test_palette_png_round_trips_greys_and_viridis(tmp_path):
    source = str(tmp_path / "grid.png")
    fake_runs.write_grid(source, width=120, height=40)
    target = str(tmp_path / "small.png")
    images.write_reduced_grid(source, target, width=60)
    got = mpimg.imread(target)[..., :3]
    want = images.reduce_width(mpimg.imread(source)[..., :3].astype(float), 60)
    assert got.shape == want.shape == (20, 60, 3)
    # Greys: rounding to 8 bits (half a level) plus the palette's step of 255/127 levels.
    assert np.abs(got[:10] - want[:10]).max() * 255 <= 0.5 + 255 / 127 / 2 + 1e-3
    assert np.abs(got - want).mean() * 255 < 2.0


def test_heat_map_colour_bar_has_tick_values(tmp_path):
    ticks = plots.heat_map_colour_bar(str(tmp_path / "bar.png"), 20.0)
    assert [float(t) for t in ticks] == [0, 5, 10, 15, 20]
    assert [float(t) for t in plots.heat_map_colour_bar(str(tmp_path / "bar2.png"), 30.0)] == [0, 7.5, 15, 22.5, 30]
    assert (tmp_path / "bar.png").stat().st_size > 1000


def test_log_log_plot_is_written(tmp_path):
    plots.log_log(str(tmp_path / "p.png"), "t", "x", "y", [plots.Curve("a", [1, 10, 100], [1, 0.1, 0.01]),
                                                           plots.Curve("b", [2, 20], [1, 0.2], dashed=True)],
                  markers=("thesis", [5], [0.5]))
    assert mpimg.imread(str(tmp_path / "p.png")).shape[2] == 4
