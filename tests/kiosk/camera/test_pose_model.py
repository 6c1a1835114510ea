"""The real pose model (MediaPipe Pose, full model, from the installed wheel) on real pictures: a
whole standing figure passes the whole-body check, a half-body portrait and the same figure with its
legs cut off do not (the model still places the hips there), and the camera channel follows it."""

from __future__ import annotations

import queue
from pathlib import Path

import numpy as np
import pytest

from kiosk.camera import CameraChannel, Frame, MediapipePose, Presence, model_problem
from kiosk.core.channels import ChannelState
from kiosk.core.tug.framing import framing_problem, missing_parts
from kiosk.core.tug.landmarks import INDEX

pytestmark = pytest.mark.slow  # loads a neural network

DATA = Path(__file__).parent / "data"


@pytest.fixture(scope="module")
def model():
    assert model_problem() == "", model_problem()  # installed by `uv sync` (pyproject.toml)
    estimator = MediapipePose(still=True)
    yield estimator
    estimator.close()


def picture(name: str) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(DATA / name).convert("RGB"))


def test_a_whole_standing_figure_is_seen_whole(model):
    landmarks = model.estimate(Frame(0.0, picture("full_body.png")))
    assert landmarks is not None and len(landmarks) == 33
    assert framing_problem(landmarks) == ""
    ankle, hip = landmarks[INDEX["left_ankle"]], landmarks[INDEX["left_hip"]]
    assert ankle[1] > hip[1] + 0.2  # the feet are well below the hips, in image fractions


def test_a_half_body_portrait_is_not_a_whole_body(model):
    from skimage import data

    landmarks = model.estimate(Frame(0.0, np.ascontiguousarray(data.astronaut())))
    assert landmarks is not None
    assert {"knees", "ankles", "heels"} <= set(missing_parts(landmarks))
    assert framing_problem(landmarks).startswith("not the whole body")


def test_legs_cut_off_fail_the_check_though_the_hips_are_placed(model):
    whole = picture("full_body.png")
    top = np.ascontiguousarray(whole[: int(whole.shape[0] * 0.55)])
    landmarks = model.estimate(Frame(0.0, top))
    assert landmarks is not None
    assert max(landmarks[INDEX["left_hip"]][3], landmarks[INDEX["right_hip"]][3]) > 0.5
    assert "ankles" in missing_parts(landmarks)


def test_the_channel_follows_the_real_model_and_tells_when_the_person_goes():
    whole = picture("full_body.png")
    empty = np.full_like(whole, 235)
    pictures = [whole] * 8 + [empty] * 8

    class Pictures:
        name = "pictures"

        def read(self):
            return Frame(t=(16 - len(pictures)) / 4, image=pictures.pop(0)) if pictures else None

        def close(self):
            pass

    found: list[bool] = []
    changes: list[bool] = []
    channel = CameraChannel(
        Pictures,
        lambda: MediapipePose(still=True),
        on_pose=lambda reading: found.append(reading.landmarks is not None),
        on_presence=changes.append,
        presence=Presence(away_s=1.0, back_s=0.5),
    )
    statuses: queue.Queue = queue.Queue()
    channel.start(statuses.put)
    channel.join(120)
    assert found == [True] * 8 + [False] * 8
    assert changes == [True, False]
    states = [statuses.get_nowait().state for _ in range(statuses.qsize())]
    assert states == [ChannelState.CONNECTING, ChannelState.ON, ChannelState.LOST]
