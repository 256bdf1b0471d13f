"""The summary `synthua generate` prints: worker time by phase, the render's parts inside it."""

from synthua_usd.cli.dataset_commands import worker_time_shares


def test_render_parts_are_shares_of_the_whole_and_not_counted_twice():
    seconds = {"render": 8.0, "annotate": 1.0, "write": 1.0, "render_rgb": 5.0, "render_denoise": 2.0,
               "render_labels": 0.0}
    assert worker_time_shares(seconds) == "render 80 % (rgb 50 %, denoise 20 %), annotate 10 %, write 10 %"


def test_without_parts_or_time():
    assert worker_time_shares({"render": 3.0, "annotate": 1.0}) == "render 75 %, annotate 25 %"
    assert worker_time_shares({"render": 0.0, "annotate": 0.0, "write": 0.0}) == "render 0 %, annotate 0 %, write 0 %"
