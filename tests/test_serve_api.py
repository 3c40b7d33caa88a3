"""``simdiff serve``: the JSON API end to end over HTTP (server in a thread on port 0, urllib)."""

from __future__ import annotations

import argparse
import io
import json
import socket
import threading
import urllib.error
import urllib.request
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import torch

from simdiff.cli.main import main
from simdiff.diffusion.config import SamplingConfig
from simdiff.errors import SimdiffError
from simdiff.inference.generator import MotionGenerator
from simdiff.motion import synthetic
from simdiff.motion.features import features_to_joints, joints_to_features
from simdiff.motion.io import load_joints, write_bvh
from simdiff.motion.rigid import joints_from_features
from simdiff.motion.skeleton import PARENTS
from simdiff.serve import ListedMotion, MotionService, ViewerServer, parse_generate
from simdiff.serve.testing import write_tiny_model
from simdiff.train.testing import HashTextEncoder

STEPS = 4  # DDIM steps per test generation: enough to exercise the sampler, fast on a busy CPU


@pytest.fixture(scope="module", autouse=True)
def one_thread():
    threads = torch.get_num_threads()
    torch.set_num_threads(1)  # a tiny model on a loaded 2-core machine is far faster single-threaded
    yield
    torch.set_num_threads(threads)


@pytest.fixture(scope="module")
def model_dir(tmp_path_factory) -> Path:
    return write_tiny_model(tmp_path_factory.mktemp("tiny_model"))


@pytest.fixture(scope="module")
def walk() -> np.ndarray:
    return synthetic.walk(30, turn_rate=0.3)


def _start(service: MotionService) -> ViewerServer:
    server = ViewerServer(service, "127.0.0.1", 0)
    server.start_in_thread()
    return server


@pytest.fixture(scope="module")
def server(model_dir, walk):
    listed = [ListedMotion("walk.npy", Path("walk.npy"), walk)]
    srv = _start(MotionService(model_dir, files=listed, text_encoder=HashTextEncoder(), steps=STEPS))
    yield srv
    srv.shutdown()
    srv.server_close()


def call(server: ViewerServer, path: str, body: Any = None, *, content_type: str | None = None,
         headers: dict[str, str] | None = None) -> tuple[int, Any, str]:
    """(status, decoded JSON or text, content type) of one request."""
    data = None
    headers = dict(headers or {})
    if body is not None:
        data = body if isinstance(body, bytes) else json.dumps(body).encode()
        headers.setdefault("Content-Type", content_type or ("application/octet-stream" if isinstance(body, bytes) else "application/json"))
    request = urllib.request.Request(server.url + path.lstrip("/"), data=data, headers=headers)
    try:
        with urllib.request.urlopen(request, timeout=60) as response:
            status, raw, ctype = response.status, response.read(), response.headers["Content-Type"]
    except urllib.error.HTTPError as exc:
        status, raw, ctype = exc.code, exc.read(), exc.headers["Content-Type"]
    return status, (json.loads(raw) if ctype == "application/json" else raw.decode()), ctype


def npy_bytes(array: np.ndarray) -> bytes:
    buffer = io.BytesIO()
    np.save(buffer, array)
    return buffer.getvalue()


# -- page ---------------------------------------------------------------------------------------


def test_page_and_assets_are_served(server):
    status, page, ctype = call(server, "/")
    assert status == 200 and ctype.startswith("text/html")
    assert '<canvas id="view">' in page and "/static/ui.js" in page
    for name in ("player.js", "api.js", "ui.js"):
        status, text, ctype = call(server, f"/static/{name}")
        assert status == 200 and ctype.startswith("text/javascript") and len(text) > 200
    assert call(server, "/static/style.css")[0] == 200
    assert call(server, "/static/../service.py")[0] == 404
    assert call(server, "/static/missing.js")[0] == 404
    assert call(server, "/api/nothing")[0] == 404


def test_info_reports_model_files_limits_skeleton(server, model_dir):
    status, info, _ = call(server, "/api/info")
    assert status == 200
    assert info["model"] == {"path": str(model_dir), "found": True, "loaded": info["model"]["loaded"],
                             "kind": "simdiff", "env": True, "error": None}
    assert info["files"] == [{"index": 0, "name": "walk.npy", "frames": 30}]
    assert info["limits"]["gravity"] == [-20.0, -1.0] and info["limits"]["wind"] == 10.0
    assert info["limits"]["alpha"] == [0.0, 2.0] and info["limits"]["seconds"] == pytest.approx(9.8)
    assert info["limits"]["min_seconds"] == 0.5 and info["limits"]["upload_bytes"] == 32 * 2**20
    assert info["limits"]["open_frames"] == 12000
    assert info["defaults"]["gravity"] == pytest.approx(-9.81)
    assert info["skeleton"]["parents"] == list(PARENTS)


# -- generate -----------------------------------------------------------------------------------


def test_generate_matches_direct_sampling(server, model_dir):
    body = {"text": "a person  jumps forward", "gravity": -5.0, "wind_x": 3.0, "wind_y": -2.0, "alpha": 1.5,
            "seconds": 2.0, "seed": 7}
    status, out, _ = call(server, "/api/generate", body)
    assert status == 200, out
    joints = np.asarray(out["joints"])
    assert joints.shape == (40, 22, 3) and out["fps"] == 20 and out["parents"] == list(PARENTS)
    meta = out["meta"]
    assert meta["source"] == "generate" and meta["frames"] == 40 and meta["seconds"] == 2.0 and meta["env_used"]
    assert isinstance(meta["touches_floor"], bool) and isinstance(meta["lowest_m"], float)
    assert meta["params"]["text"] == "a person jumps forward" and meta["sampling"]["steps"] == STEPS

    gen = MotionGenerator.load(model_dir, load_text=False)
    gen.text_encoder = HashTextEncoder()
    config = SamplingConfig(steps=STEPS, alpha=1.5)
    clip = gen.generate(["a person jumps forward"], 40, config, env=(-5.0, 3.0, -2.0), seed=7).clips()[0]
    expected = joints_from_features(clip.numpy())  # the joints `simdiff generate` writes
    np.testing.assert_allclose(joints, expected, atol=1e-4)  # rounded to 0.1 mm on the wire
    assert meta["sampling"] == config.to_dict()  # no sampling.json: the SamplingConfig defaults, as `simdiff generate`
    status, out, _ = call(server, "/api/generate", {**body, "foot_lock": 1.0})
    assert status == 200 and out["meta"]["sampling"]["foot_lock"] == 1.0
    locked = gen.generate(["a person jumps forward"], 40, replace(config, foot_lock=1.0), env=(-5.0, 3.0, -2.0),
                          seed=7).clips()[0]
    np.testing.assert_allclose(np.asarray(out["joints"]), joints_from_features(locked.numpy(), 1.0), atol=1e-4)


def test_generate_with_simulated_finish(server):
    body = {"text": "a person jumps", "gravity": -3.0, "seconds": 0.5, "seed": 1, "simulate": True}
    status, out, _ = call(server, "/api/generate", body)
    assert status == 200, out
    meta = out["meta"]
    generated = np.asarray(meta["generated_joints"])
    assert generated.shape == (10, 22, 3) and meta["params"]["simulate"] is True
    sim = meta["simulated"]
    assert sim["env"] == [-3.0, 0.0, 0.0] and sim["n_frames"] == 10 and sim["status"] in ("ok", "fell", "unstable")
    assert np.asarray(out["joints"]).shape == (sim["n_out"], 22, 3)  # the simulated motion is the one shown


def test_same_seed_repeats_and_gravity_changes_the_motion(server):
    body = {"text": "a person walks", "seconds": 1.5, "seed": 3}
    first = np.asarray(call(server, "/api/generate", body)[1]["joints"])
    again = call(server, "/api/generate", body)[1]
    assert np.array_equal(first, np.asarray(again["joints"]))
    moon = np.asarray(call(server, "/api/generate", {**body, "gravity": -1.62})[1]["joints"])
    assert first.shape == moon.shape == (30, 22, 3)
    assert np.abs(first - moon).max() > 1e-3  # the adapters react to φ
    windy = np.asarray(call(server, "/api/generate", {**body, "wind_y": 10.0})[1]["joints"])
    assert np.abs(first - windy).max() > 1e-3


def test_generation_requests_are_serialised(server):
    results: list[tuple[int, Any, str]] = []
    threads = [threading.Thread(target=lambda s=s: results.append(call(server, "/api/generate", {"text": "run", "seconds": 1, "seed": s})))
               for s in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert [r[0] for r in results] == [200, 200, 200]
    ids = sorted(r[1]["meta"]["id"] for r in results)
    assert ids == list(range(ids[0], ids[0] + 3))


@pytest.mark.parametrize("body, needle", [
    ({"text": "  "}, "text must be a non-empty prompt"),
    ({"gravity": -9.81}, "text must be a non-empty prompt"),
    ({"text": "walk", "gravity": -25}, "gravity must be in [-20, -1] m/s², got -25"),
    ({"text": "walk", "gravity": 0}, "gravity must be in [-20, -1]"),
    ({"text": "walk", "wind_x": 10.5}, "wind_x must be in [-10, 10] N, got 10.5"),
    ({"text": "walk", "wind_y": -11}, "wind_y must be in [-10, 10] N, got -11"),
    ({"text": "walk", "alpha": 2.5}, "alpha must be in [0, 2], got 2.5"),
    ({"text": "walk", "seconds": 10}, "seconds must be in [0.5, 9.8], got 10"),
    ({"text": "walk", "seconds": 0.1}, "seconds must be in [0.5, 9.8], got 0.1"),
    ({"text": "walk", "seconds": 0}, "seconds must be in"),
    ({"text": "walk", "gravity": "low"}, "gravity must be a finite number, got 'low'"),
    ({"text": "walk", "seed": 1.5}, "seed must be an integer, got 1.5"),
    ({"text": "walk", "seed": -1}, "seed must be a non-negative integer"),
    ({"text": "walk", "steps": 0}, "steps must be in [1, 200], got 0"),
    ({"text": "walk", "windx": 1}, "unknown field 'windx'"),
    ({"text": "walk", "simulate": "yes"}, "simulate must be true or false, got 'yes'"),
    ({"text": "walk", "foot_lock": 2}, "foot_lock must be in [0, 1], got 2"),
    ({"text": "walk", "foot_lock": "on"}, "foot_lock must be a finite number, got 'on'"),
    (["walk"], "request body must be a JSON object"),
])
def test_bad_generate_request_is_a_400_with_one_line(server, body, needle):
    status, out, _ = call(server, "/api/generate", body)
    assert status == 400
    assert needle in out["error"] and "\n" not in out["error"]


def test_generate_needs_json(server):
    status, out, _ = call(server, "/api/generate", b'{"text": "walk"}', content_type="text/plain")
    assert status == 415 and "application/json" in out["error"]
    status, out, _ = call(server, "/api/generate", b"{text: walk", content_type="application/json")
    assert status == 400 and out["error"].startswith("request body is not valid JSON")


def test_foreign_host_and_origin_are_refused(server):
    status, out, _ = call(server, "/api/info", headers={"Host": "evil.example"})
    assert status == 403 and "evil.example" in out["error"]
    status, out, _ = call(server, "/api/generate", {"text": "walk"}, headers={"Origin": "http://evil.example"})
    assert status == 403 and "cross-origin" in out["error"]
    assert call(server, "/api/info", headers={"Host": f"localhost:{server.port}"})[0] == 200


def test_parse_generate_defaults_and_frames():
    params = parse_generate({"text": " a  person\twaves "})
    assert params.text == "a person waves" and params.frames == 120 and params.gravity == pytest.approx(-9.81)
    assert parse_generate({"text": "x", "seconds": 9.8, "seed": 2.0}).frames == 196
    assert parse_generate({"text": "x", "seconds": 0.5}).frames == 10
    with pytest.raises(SimdiffError, match="alpha"):
        parse_generate({"text": "x", "alpha": float("nan")})


def test_no_model_answers_503_and_files_still_open(tmp_path, walk):
    srv = _start(MotionService(tmp_path / "nowhere", files=[ListedMotion("w.npy", Path("w.npy"), walk)]))
    try:
        info = call(srv, "/api/info")[1]
        assert info["model"]["found"] is False and "nowhere" in info["model"]["error"]
        status, out, _ = call(srv, "/api/generate", {"text": "walk"})
        assert status == 503 and str(tmp_path / "nowhere") in out["error"]
        assert call(srv, "/api/files/0")[0] == 200
    finally:
        srv.shutdown()
        srv.server_close()


def test_far_prompts_carry_the_generate_warning(tmp_path, model_dir):
    import shutil

    from simdiff.inference.coverage import write_coverage_table

    folder = tmp_path / "model"
    shutil.copytree(model_dir, folder)
    write_coverage_table(folder, ["a person walks forward.", "a person jumps."], HashTextEncoder())
    srv = _start(MotionService(folder, text_encoder=HashTextEncoder(), steps=STEPS))
    try:
        status, out, _ = call(srv, "/api/generate", {"text": "a person jumps.", "seconds": 1.0})
        assert status == 200 and out["meta"]["warnings"] == []
        status, out, _ = call(srv, "/api/generate", {"text": "a person plays the violin", "seconds": 1.0})
        assert status == 200 and len(out["meta"]["warnings"]) == 1
        assert out["meta"]["warnings"][0].startswith('"a person plays the violin" is far from every training caption')
        segments = [{"text": "a person jumps.", "seconds": 1}, {"text": "a person plays the violin", "seconds": 1}]
        status, out, _ = call(srv, "/api/timeline", {"segments": segments})
        assert status == 200 and [w.split('"')[1] for w in out["meta"]["warnings"]] == ["a person plays the violin"]
    finally:
        srv.shutdown()
        srv.server_close()


# -- files --------------------------------------------------------------------------------------


def test_open_uploaded_joints_features_and_bvh(server, walk, tmp_path):
    status, out, _ = call(server, "/api/open?name=walk.npy", npy_bytes(walk))
    assert status == 200 and out["meta"]["source"] == "upload" and out["meta"]["name"] == "walk.npy"
    np.testing.assert_allclose(np.asarray(out["joints"]), walk, atol=1e-4)

    features = joints_to_features(walk)
    status, out, _ = call(server, "/api/open?name=feats.npy", npy_bytes(features))
    assert status == 200 and out["meta"]["frames"] == 29
    np.testing.assert_allclose(np.asarray(out["joints"]), features_to_joints(features), atol=1e-4)

    bvh = write_bvh(tmp_path / "walk.bvh", walk)
    status, out, _ = call(server, "/api/open?name=walk.bvh", bvh.read_bytes())
    assert status == 200, out
    np.testing.assert_allclose(np.asarray(out["joints"]), load_joints(bvh), atol=1e-4)


@pytest.mark.parametrize("name, data, needle", [
    ("bad.npy", npy_bytes(np.zeros((5, 7), np.float32)), "bad.npy: expected (T, 22, 3) joints or (T, 263) features"),
    ("junk.bvh", b"\x00\xff not a bvh", "junk.bvh"),
    ("model.exe", b"MZ", "model.exe: unsupported file type '.exe'"),
    ("empty.npy", b"", "empty.npy: empty file"),
    ("", b"xx", "upload needs a file name"),
])
def test_bad_upload_is_a_400_naming_the_file(server, name, data, needle):
    status, out, _ = call(server, f"/api/open?name={name}", data)
    assert status == 400
    assert needle in out["error"] and "simdiff-serve-" not in out["error"]  # never the temp path


def test_listed_files_open_by_index(server, walk):
    status, out, _ = call(server, "/api/files/0")
    assert status == 200 and out["meta"] == {"source": "file", "name": "walk.npy", "path": "walk.npy", "frames": 30, "seconds": 1.5}
    np.testing.assert_allclose(np.asarray(out["joints"]), walk, atol=1e-4)
    status, out, _ = call(server, "/api/files/3")
    assert status == 400 and "no listed file 3" in out["error"]


# -- command line -------------------------------------------------------------------------------


def test_cli_missing_file_is_a_one_line_error(tmp_path, capsys):
    assert main(["serve", str(tmp_path / "missing.npy"), "--no-browser", "--port", "0"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("simdiff: error:") and "missing.npy" in err and "\n" not in err


def test_cli_builds_a_server_with_listed_files(tmp_path, walk, model_dir):
    from simdiff.cli.commands.serve import build_server

    np.save(tmp_path / "walk.npy", walk)
    args = argparse.Namespace(files=[tmp_path / "walk.npy"], port=0, host="127.0.0.1", model=model_dir,
                              device="cpu", steps=None, queue=4, no_browser=True)
    srv = build_server(args)
    srv.verbose = False
    srv.start_in_thread()
    try:
        assert srv.url == f"http://127.0.0.1:{srv.port}/" and srv.port > 0
        info = call(srv, "/api/info")[1]
        assert info["files"][0]["name"] == "walk.npy" and info["model"]["kind"] == "simdiff"
        with socket.socket() as busy:  # a taken port is a one-line error naming it
            busy.bind(("127.0.0.1", 0))
            busy.listen()
            taken = busy.getsockname()[1]
            with pytest.raises(SimdiffError, match=f"port {taken} on 127.0.0.1 is already in use"):
                build_server(argparse.Namespace(**{**vars(args), "files": [], "port": taken}))
    finally:
        srv.shutdown()
        srv.server_close()


def test_cli_rejects_bad_port_and_steps(capsys):
    assert main(["serve", "--port", "70000", "--no-browser"]) == 2
    err = capsys.readouterr().err
    assert "--port" in err and "70000" in err and "0..65535" in err
    assert main(["serve", "--steps", "0", "--no-browser"]) == 2
    err = capsys.readouterr().err
    assert "--steps" in err and "1..1000" in err


def test_generate_takes_the_models_alpha_and_foot_lock_unless_given(server, model_dir):
    body = {"text": "a person walks", "seconds": 1.0, "seed": 3}
    assert call(server, "/api/info")[1]["defaults"]["alpha"] == 1.0  # no sampling.json: α 1, no lock
    (model_dir / "sampling.json").write_text('{"alpha": 0.5, "foot_lock": 1.0}')
    try:
        defaults = call(server, "/api/info")[1]["defaults"]
        assert (defaults["alpha"], defaults["foot_lock"]) == (0.5, 1.0)  # the page starts where `generate` does
        status, stored, _ = call(server, "/api/generate", body)
        assert status == 200 and stored["meta"]["sampling"]["foot_lock"] == 1.0
        assert stored["meta"]["sampling"]["alpha"] == 0.5
        status, given, _ = call(server, "/api/generate", {**body, "alpha": 0.5, "foot_lock": 1})
        assert given["joints"] == stored["joints"]
        status, off, _ = call(server, "/api/generate", {**body, "foot_lock": 0})
        assert status == 200 and off["meta"]["sampling"]["foot_lock"] == 0.0
        (model_dir / "sampling.json").write_text('{"foot_lock": 3}')
        status, out, _ = call(server, "/api/generate", body)
        assert status == 503 and "--foot-lock must be in [0, 1], got 3" in out["error"]
        assert call(server, "/api/info")[0] == 200  # the page still loads its defaults
    finally:
        (model_dir / "sampling.json").unlink()


def test_generate_env_guidance_from_sampling_json_or_the_request(server, model_dir):
    moon = {"text": "a person jumps", "seconds": 1.0, "seed": 3, "gravity": -1.6}
    status, plain, _ = call(server, "/api/generate", moon)
    assert status == 200 and plain["meta"]["sampling"]["env_guidance"] == 1.0
    status, pushed, _ = call(server, "/api/generate", {**moon, "env_guidance": 3})
    assert status == 200 and pushed["meta"]["sampling"]["env_guidance"] == 3.0 and pushed["joints"] != plain["joints"]
    earth = {**moon, "gravity": -9.81}
    assert call(server, "/api/generate", {**earth, "env_guidance": 3})[1]["joints"] == \
        call(server, "/api/generate", earth)[1]["joints"]  # Earth without wind: unchanged
    (model_dir / "sampling.json").write_text('{"env_guidance": 3}')
    try:
        assert call(server, "/api/info")[1]["defaults"]["env_guidance"] == 3.0
        status, stored, _ = call(server, "/api/generate", moon)
        assert status == 200 and stored["joints"] == pushed["joints"]
    finally:
        (model_dir / "sampling.json").unlink()
    for bad in (-1, 11, "x"):
        status, out, _ = call(server, "/api/generate", {**moon, "env_guidance": bad})
        assert status == 400 and "env_guidance" in out["error"]


def test_generate_edit_t_from_sampling_json_or_the_request(server, model_dir):
    moon = {"text": "a person jumps", "seconds": 1.0, "seed": 3, "alpha": 0.5, "gravity": -1.6}
    status, given, _ = call(server, "/api/generate", {**moon, "edit_t": 100})
    assert status == 200 and given["meta"]["sampling"]["edit_t"] == 100
    assert given["joints"] != call(server, "/api/generate", moon)[1]["joints"]
    (model_dir / "sampling.json").write_text('{"edit_t": 100}')
    try:
        status, stored, _ = call(server, "/api/generate", moon)
        assert status == 200 and stored["joints"] == given["joints"]
    finally:
        (model_dir / "sampling.json").unlink()
    for bad, message in ((1000, "edit_t must be in [0, 999], got 1000"), (2.5, "edit_t must be an integer")):
        status, out, _ = call(server, "/api/generate", {**moon, "edit_t": bad})
        assert status == 400 and message in out["error"], out


def test_generate_guidance_min_t_from_the_request(server, model_dir):
    walk = {"text": "a person walks", "seconds": 1.0, "seed": 3, "guidance": 2.0}
    status, early, _ = call(server, "/api/generate", {**walk, "guidance_min_t": 999})
    assert status == 200 and early["meta"]["sampling"]["guidance_min_t"] == 999
    assert early["joints"] != call(server, "/api/generate", walk)[1]["joints"]  # unguided at every step below 999
    status, out, _ = call(server, "/api/generate", {**walk, "guidance_min_t": -1})
    assert status == 400 and "guidance_min_t must be in [0, 999], got -1" in out["error"], out


def test_the_viewer_and_the_cli_give_the_same_joints(server, model_dir, tmp_path):
    """Same prompt, seed and φ, the model's sampling.json for both (non-round values, as the shipped model's):
    the viewer's joints are the CLI's (to the 0.1 mm the wire rounds to)."""
    from unittest import mock

    (model_dir / "sampling.json").write_text('{"steps": 4, "eta": 1.0, "guidance": 3.0, "alpha": 0.925, '
                                             '"env_guidance": 1.1, "edit_t": 950, "foot_lock": 1.0}')
    try:
        defaults = call(server, "/api/info")[1]["defaults"]
        assert (defaults["alpha"], defaults["env_guidance"], defaults["guidance"]) == (0.925, 1.1, 3.0)
        body = {"text": "a person jumps forward", "gravity": -3.7, "wind_x": 2.0, "seconds": 1.0, "seed": 5}
        status, viewer, _ = call(server, "/api/generate", body)
        assert status == 200, viewer
        # the page sends its sliders, which start at the model's exact values: the same motion
        sliders = {k: defaults[k] for k in ("alpha", "env_guidance", "guidance", "foot_lock")}
        assert call(server, "/api/generate", {**body, **sliders})[1]["joints"] == viewer["joints"]
        with mock.patch("simdiff.text.base.load_text_encoder", return_value=HashTextEncoder()):
            code = main(["generate", body["text"], "--gravity", "-3.7", "--wind", "2", "0", "--length", "1",
                         "--seed", "5", "--model", str(model_dir), "--format", "npy", "--out", str(tmp_path), "-q"])
        assert code == 0
    finally:
        (model_dir / "sampling.json").unlink()
    cli = np.load(tmp_path / "sample0_joints.npy")
    np.testing.assert_allclose(np.asarray(viewer["joints"]), cli, atol=1e-4)


def test_generate_eta_from_sampling_json_or_the_request(server, model_dir):
    moon = {"text": "a person jumps", "seconds": 1.0, "seed": 3, "alpha": 0.5, "gravity": -1.6}
    status, plain, _ = call(server, "/api/generate", moon)
    assert status == 200 and plain["meta"]["sampling"]["eta"] == 0.0
    status, noisy, _ = call(server, "/api/generate", {**moon, "eta": 1.0})
    assert status == 200 and noisy["meta"]["sampling"]["eta"] == 1.0 and noisy["joints"] != plain["joints"]
    (model_dir / "sampling.json").write_text('{"eta": 1.0}')
    try:
        status, stored, _ = call(server, "/api/generate", moon)
        assert status == 200 and stored["joints"] == noisy["joints"]
        assert call(server, "/api/generate", {**moon, "eta": 0})[1]["joints"] == plain["joints"]  # the request wins
    finally:
        (model_dir / "sampling.json").unlink()
    for bad, message in ((1.5, "eta must be in [0, 1], got 1.5"), ("x", "eta must be a finite number")):
        status, out, _ = call(server, "/api/generate", {**moon, "eta": bad})
        assert status == 400 and message in out["error"], out


# -- re-play, timeline, pins --------------------------------------------------------------------


def _tiny_generator(model_dir: Path) -> MotionGenerator:
    gen = MotionGenerator.load(model_dir, load_text=False)
    gen.text_encoder = HashTextEncoder()
    return gen


def test_answers_are_numbered_and_name_their_body(server):
    status, out, _ = call(server, "/api/files/0")
    assert status == 200 and isinstance(out["motion"], int) and out["body"] == f"/api/body/{out['motion']}.glb"
    again = call(server, "/api/files/0")[1]
    assert again["motion"] == out["motion"] + 1


def test_edit_replays_a_motion_shown_as_simdiff_edit_does(server, model_dir):
    from simdiff.inference.editing import edit_motion
    from simdiff.motion.gravity_readout import read_gravity

    opened = call(server, "/api/files/0")[1]
    body = {"source": opened["motion"], "gravity": -1.6, "wind_x": 2.0, "seed": 4, "alpha": 1.5}
    status, out, _ = call(server, "/api/edit", body)
    assert status == 200, out
    meta = out["meta"]
    assert meta["source"] == "edit" and meta["params"] == {**body, "wind_y": 0.0, "text": ""}
    assert meta["frames"] == 30 and meta["sampling"]["alpha"] == 1.5 and meta["sampling"]["steps"] == STEPS
    assert meta["queue_position"] == 0 and isinstance(meta["id"], int) and out["motion"] > opened["motion"]
    source = np.asarray(opened["joints"])  # the joints as the page has them
    config = SamplingConfig(steps=STEPS, alpha=1.5)
    expected = edit_motion(_tiny_generator(model_dir), source, config, (-1.6, 2.0, 0.0), seed=4)
    np.testing.assert_allclose(np.asarray(out["joints"]), expected.joints, atol=1e-4)
    read = {"input": read_gravity(source), "edited": read_gravity(expected.joints)}  # as edit.json reads them
    assert set(meta["gravity_read"]) == {"input", "edited"}
    for key, value in read.items():
        assert meta["gravity_read"][key] == (None if value is None else pytest.approx(value))
    assert meta["changed_m"] == pytest.approx(expected.changed_m, abs=1e-4) and meta["changed_m"] > 0.001
    # at Earth without wind the motion comes back (fitted on its own skeleton); a re-play of a re-play works too
    status, earth, _ = call(server, "/api/edit", {"source": opened["motion"]})
    assert status == 200 and earth["meta"]["changed_m"] < 0.02
    assert call(server, "/api/edit", {"source": out["motion"], "gravity": -3.7})[0] == 200


def test_edit_refuses_a_source_it_does_not_keep_or_cannot_replay(server, walk, monkeypatch):
    status, out, _ = call(server, "/api/edit", {"source": 999999})
    assert status == 400 and out["error"].startswith("source 999999: no such motion here")
    short = call(server, "/api/open?name=short.npy", npy_bytes(walk[:5]))[1]
    status, out, _ = call(server, "/api/edit", {"source": short["motion"], "gravity": -3})
    assert status == 400 and f"source {short['motion']} has 5 frames; editing needs at least 10" in out["error"]
    tiny = call(server, "/api/open?name=tiny.npy", npy_bytes(walk * 0.01))[1]  # centimetres taken for metres
    status, out, _ = call(server, "/api/edit", {"source": tiny["motion"], "gravity": -3})
    assert status == 400 and "not a body in metres" in out["error"]
    monkeypatch.setattr("simdiff.serve.edits.MAX_REPLAY_FRAMES", 20)
    opened = call(server, "/api/files/0")[1]
    status, out, _ = call(server, "/api/edit", {"source": opened["motion"], "gravity": -3})
    assert status == 400 and "has 30 frames; the viewer re-plays up to 20 (1 s): use simdiff edit" in out["error"]


@pytest.mark.parametrize("body, needle", [
    ({}, "source must be the number of a motion shown"),
    ({"source": "1"}, "source must be the number of a motion shown (an answer's \"motion\"), got '1'"),
    ({"source": True}, "source must be the number of a motion shown"),
    ({"source": 0}, "got 0"),
    ({"source": 1.5}, "got 1.5"),
    ({"source": 1, "gravity": -25}, "gravity must be in [-20, -1] m/s², got -25"),
    ({"source": 1, "gravity": "moon"}, "gravity must be a finite number, got 'moon'"),
    ({"source": 1, "wind_x": 11}, "wind_x must be in [-10, 10] N, got 11"),
    ({"source": 1, "seed": -1}, "seed must be a non-negative integer"),
    ({"source": 1, "edit_t": 1000}, "edit_t must be in [0, 999], got 1000"),
    ({"source": 1, "text": 5}, "text must be a non-empty prompt, got 5"),
    ({"source": 1, "seconds": 2}, "unknown field 'seconds'"),
    ([1], "request body must be a JSON object, got list"),
])
def test_bad_edit_request_is_a_400_with_one_line(server, body, needle):
    status, out, _ = call(server, "/api/edit", body)
    assert status == 400 and needle in out["error"] and "\n" not in out["error"], out


def test_edit_refuses_non_finite_json(server):
    status, out, _ = call(server, "/api/edit", b'{"source": 1, "gravity": NaN}', content_type="application/json")
    assert status == 400 and "NaN" in out["error"]


def test_timeline_is_the_clis_timeline(server, model_dir):
    from simdiff.inference.timeline import sample_timeline
    from simdiff.product.request import parse_timeline

    segments = [{"text": "a person walks forward", "seconds": 1.5},
                {"text": "a person jumps", "seconds": 1, "gravity": -1.6, "wind": [0, 4]}]
    status, out, _ = call(server, "/api/timeline", {"segments": segments, "seed": 3})
    assert status == 200, out
    meta = out["meta"]
    assert meta["source"] == "timeline" and meta["frames"] == 50 and meta["seed"] == 3 and meta["env_used"]
    assert meta["segments"] == [
        {"text": "a person walks forward", "frames": [0, 30], "gravity": -9.81, "wind": [0.0, 0.0]},
        {"text": "a person jumps", "frames": [30, 50], "gravity": -1.6, "wind": [0.0, 4.0]}]
    _, joints = sample_timeline(_tiny_generator(model_dir), parse_timeline(segments), SamplingConfig(steps=STEPS),
                                seed=3)
    np.testing.assert_allclose(np.asarray(out["joints"]), joints, atol=1e-4)
    assert isinstance(out["motion"], int) and out["body"].endswith(".glb")


BAD_SEGMENTS = [
    None,
    [],
    "walk",
    [{"text": "walk"}],
    [{"seconds": 2}],
    [{"text": "   ", "seconds": 2}],
    [{"text": "walk", "seconds": 20}],
    [{"text": "walk", "seconds": 0.1}],
    [{"text": "walk", "seconds": 2}, {"text": "run", "seconds": 9.5}],
    [{"text": "walk", "seconds": 2, "gravity": 3}],
    [{"text": "walk", "seconds": 2, "gravity": "moon"}],
    [{"text": "walk", "seconds": 2, "wind": [20, 0]}],
    [{"text": "walk", "seconds": 2, "wind": 3}],
    [{"text": "walk", "seconds": 2, "prompt": "x"}],
    [{"text": "walk", "seconds": 2}, "run"],
    [{"text": 5, "seconds": 2}],
    [{"text": "walk", "seconds": 10**30}],
]


@pytest.mark.parametrize("segments", BAD_SEGMENTS, ids=range(len(BAD_SEGMENTS)))
def test_bad_timeline_is_refused_with_the_clis_message(server, segments):
    from simdiff.product.request import parse_timeline

    with pytest.raises(SimdiffError) as cli:
        parse_timeline(segments)
    status, out, _ = call(server, "/api/timeline", {"segments": segments} if segments is not None else {})
    assert status == 400 and out["error"] == str(cli.value) and "\n" not in out["error"]


@pytest.mark.parametrize("body, needle", [
    ({"segments": [{"text": "walk", "seconds": 1}] * 9}, "the timeline has 9 segments; the viewer takes at most 8"),
    ({"segments": [{"text": "walk", "seconds": 1}], "seed": -2}, "seed must be a non-negative integer"),
    ({"segments": [{"text": "walk", "seconds": 1}], "gravity": -3}, "unknown field 'gravity'"),
    ({"segments": [{"text": "walk", "seconds": 1}], "steps": 500}, "steps must be in [1, 200], got 500"),
    ({"segments": [{"text": "\ud800", "seconds": 1}]}, "segment 0: text must be valid Unicode"),
    ("walk", "request body must be a JSON object, got str"),
])
def test_bad_timeline_request_is_a_400_with_one_line(server, body, needle):
    status, out, _ = call(server, "/api/timeline", body)
    assert status == 400 and needle in out["error"] and "\n" not in out["error"], out


def test_pins_start_and_end_in_a_shown_motions_poses(server, model_dir):
    from simdiff.inference.keyframes import keyframe_error, sample_keyframed

    opened = call(server, "/api/files/0")[1]
    source = np.asarray(opened["joints"])
    body = {"text": "a person walks", "seconds": 2, "seed": 1}
    status, out, _ = call(server, "/api/generate", {**body, "pin_start": opened["motion"]})
    assert status == 200, out
    joints, meta = np.asarray(out["joints"]), out["meta"]
    assert joints.shape == (40, 22, 3) and meta["pins"] == {"start": opened["motion"], "end": None}
    assert meta["params"]["pin_start"] == opened["motion"] and meta["params"]["pin_end"] is None
    assert meta["keyframe_error_cm"] < 2.0 and np.linalg.norm(joints[0] - source[0], axis=-1).max() < 0.02
    keys = np.full((40, 22, 3), np.nan)
    keys[0] = source[0]
    gen = _tiny_generator(model_dir)
    _, expected = sample_keyframed(gen, keys, SamplingConfig(steps=STEPS), text_embeddings=gen.encode_text([body["text"]]),
                                   env=(-9.81, 0.0, 0.0), seed=1)  # what `generate --keyframes` samples
    np.testing.assert_allclose(joints, expected, atol=1e-4)
    assert meta["keyframe_error_cm"] == pytest.approx(100 * keyframe_error(joints, keys), abs=0.02)

    status, out, _ = call(server, "/api/generate", {**body, "pin_start": opened["motion"], "pin_end": opened["motion"]})
    assert status == 200, out
    joints = np.asarray(out["joints"])
    assert out["meta"]["pins"] == {"start": opened["motion"], "end": opened["motion"]}
    assert np.linalg.norm(joints[[0, -1]] - source[[0, -1]], axis=-1).max() < 0.02
    assert "pins" not in call(server, "/api/generate", body)[1]["meta"]


def test_bad_pins_are_a_400_with_one_line(server, walk):
    body = {"text": "a person walks", "seconds": 2}
    for pin, needle in ((True, "pin_start must be the number of a motion shown"),
                        ("1", "pin_start must be the number of a motion shown"),
                        (-3, "got -3"), (999999, "pin_start 999999: no such motion here")):
        status, out, _ = call(server, "/api/generate", {**body, "pin_start": pin})
        assert status == 400 and needle in out["error"] and "\n" not in out["error"], out
    status, out, _ = call(server, "/api/generate", {**body, "pin_end": 999998})
    assert status == 400 and "pin_end 999998: no such motion here" in out["error"]
    # a motion that crosses 20 m: its first and last pose cannot both be met within 0.5 s
    far = walk.copy()
    far[..., 0] += np.linspace(0.0, 20.0, len(walk))[:, None]
    opened = call(server, "/api/open?name=far.npy", npy_bytes(far))[1]
    pins = {"pin_start": opened["motion"], "pin_end": opened["motion"]}
    status, out, _ = call(server, "/api/generate", {**body, "seconds": 0.5, **pins})
    assert status == 400 and out["error"].startswith("the poses pinned on a 0.5 s motion: joint 0 moves"), out
    assert "no motion reaches that" in out["error"]


def test_motions_named_as_sources_stay_kept():
    from simdiff.serve.wire import BodyCache

    cache = BodyCache(3)
    numbers = [cache.add(np.full((10, 22, 3), float(i))) for i in range(3)]
    assert cache.joints(numbers[0])[0, 0, 0] == 0.0  # used: the last to go
    cache.add(np.zeros((10, 22, 3)))
    assert cache.joints(numbers[1]) is None and cache.joints(numbers[0]) is not None
    assert cache.glb(numbers[0]) is not None and cache.joints(numbers[0]) is not None  # a built body keeps its joints


def test_edit_and_timeline_share_the_generation_queue(model_dir, walk):
    from simdiff.serve.edits import replay, timeline
    from simdiff.serve.params import parse_replay, parse_timeline_request
    from simdiff.serve.service import GenerationCancelled, QueueFull

    service = MotionService(model_dir, text_encoder=HashTextEncoder(), steps=STEPS, max_queue=0)
    source = service.answer(walk, {"source": "test"})["motion"]
    edit = parse_replay({"source": source, "gravity": -2.0})
    line = parse_timeline_request({"segments": [{"text": "walk", "seconds": 1}, {"text": "run", "seconds": 1}]})
    with service.queued(None):  # one request running, none may wait
        with pytest.raises(QueueFull):
            replay(service, edit)
        with pytest.raises(QueueFull):
            timeline(service, line)
    for run, params in ((replay, edit), (timeline, line)):  # cancelled at the third poll: during sampling
        polls = iter(range(100))
        with pytest.raises(GenerationCancelled, match="during sampling"):
            run(service, params, cancelled=lambda polls=polls: next(polls) >= 2)
        assert service.queue_status()["pending"] == 0 and service._lock.acquire(blocking=False)
        service._lock.release()
    assert replay(service, edit)["meta"]["id"] == 1  # cancelled runs take no number
