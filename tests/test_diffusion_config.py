"""SamplingConfig: the one sampling configuration, its checks and the shipped model's sampling.json."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from simdiff.diffusion.config import SamplingConfig
from simdiff.errors import SimdiffError
from simdiff.inference.default import DEFAULT_MODEL_DIR, sampling_config


def test_the_shipped_model_samples_as_documented() -> None:
    assert sampling_config(DEFAULT_MODEL_DIR) == SamplingConfig(
        sampler="ddim", steps=16, eta=1.0, guidance=3.0, guidance_min_t=749, alpha=0.925, env_guidance=1.3,
        edit_t=950, foot_lock=1.0, flight_passes=3)
    stored = json.loads((DEFAULT_MODEL_DIR / "sampling.json").read_text())
    assert stored == sampling_config(DEFAULT_MODEL_DIR).to_dict()


@pytest.mark.parametrize("kwargs, message", [
    ({"sampler": "plms"}, "--sampler must be one of ddim, ddpm, got 'plms'"),
    ({"steps": 0}, "--steps must be a whole number in 1..1000, got 0"),
    ({"steps": 2.5}, "--steps must be a whole number in 1..1000, got 2.5"),
    ({"eta": 1.5}, r"--eta must be in \[0, 1\], got 1.5"),
    ({"sampler": "ddpm", "eta": 0.5}, "--eta 0.5 is DDIM's noise scale; it needs --sampler ddim"),
    ({"guidance": math.nan}, "--guidance must be a finite number, got nan"),
    ({"guidance": -1.0}, "--guidance must be in \\[0, 20\\], got -1"),
    ({"alpha": math.inf}, "--alpha must be a finite number, got inf"),
    ({"env_guidance": -1}, "--env-guidance must be in \\[0, 10\\], got -1"),
    ({"edit_t": 1000}, "--edit-t must be a whole number in 0..999, got 1000"),
    ({"guidance_min_t": -1}, "--guidance-min-t must be a whole number in 0..999, got -1"),
    ({"edit_t": True}, "--edit-t must be a whole number in 0..999, got True"),
    ({"foot_lock": 1.5}, r"--foot-lock must be in \[0, 1\], got 1.5"),
    ({"flight_passes": 11}, "--flight-passes must be a whole number in 0..10, got 11"),
])
def test_bad_values_are_one_line_naming_the_option(kwargs: dict, message: str) -> None:
    with pytest.raises(SimdiffError, match=message) as info:
        SamplingConfig(**kwargs)
    assert "\n" not in str(info.value)


def test_updated_keeps_what_is_not_given_and_switches_sampler_defaults() -> None:
    shipped = sampling_config(DEFAULT_MODEL_DIR)
    assert shipped.updated(alpha=None, guidance=2.0) == SamplingConfig(**{**shipped.to_dict(), "guidance": 2.0})
    ddpm = shipped.updated(sampler="ddpm")
    assert (ddpm.sampler, ddpm.steps, ddpm.eta, ddpm.guidance) == ("ddpm", 1000, 0.0, 3.0)
    assert shipped.updated(sampler="ddpm", steps=100).steps == 100
    with pytest.raises(SimdiffError, match="--eta 1 is DDIM's noise scale"):
        shipped.updated(sampler="ddpm", eta=1.0)
    assert shipped.updated(steps=50, guidance_min_t=0) == SamplingConfig(
        **{**shipped.to_dict(), "steps": 50, "guidance_min_t": 0})  # the 50-step path of the model's card


@pytest.mark.parametrize("text, message", [
    ('{"anchor": "edit"}', "unknown key 'anchor' = 'edit'"),
    ('{"guidance": "high"}', "--guidance must be a finite number, got 'high'"),
    ('{"steps": [50]}', "steps = \\[50\\] is not a number"),
    ('[1]', "expected a JSON object"),
    ('{"alpha": ', "cannot read sampling settings"),
])
def test_a_bad_sampling_json_is_one_line_naming_the_file(tmp_path: Path, text: str, message: str) -> None:
    (tmp_path / "sampling.json").write_text(text)
    with pytest.raises(SimdiffError, match=message) as info:
        sampling_config(tmp_path)
    assert str(info.value).startswith(str(tmp_path / "sampling.json")) and "\n" not in str(info.value)


def test_without_a_file_the_defaults_and_no_torch(tmp_path: Path) -> None:
    assert sampling_config(tmp_path) == SamplingConfig()
    code = ("import sys\nfrom simdiff.inference.default import sampling_config\nsampling_config()\n"
            "assert 'torch' not in sys.modules, 'torch imported'\n")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
