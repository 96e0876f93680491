"""LLM and hybrid detectors end to end against the scripted OpenAI-compatible server (real HTTP)."""

from __future__ import annotations

import json

import detect_graphs as g
from test_detect_observation import assert_no_leak
from test_detect_stage import standard_run

from anomalygen.config import load_settings
from anomalygen.detect.hybrid import HybridDetector
from anomalygen.detect.stage import run_stage
from anomalygen.evaluate.text_judge import text_judge_diagnostic
from anomalygen.llm import get_client
from anomalygen.runfolder import read_jsonl
from anomalygen.schema import Detection
from support.fixtures import llm_config_for
from support.openai_server import status, text


def _user(req) -> str:
    return next(m["content"] for m in req["messages"] if m["role"] == "user")


def _system(req) -> str:
    return next((m["content"] for m in req["messages"] if m["role"] == "system"), "")


def reply(*hyps):
    return text(json.dumps({"hypotheses": [
        {"problem": p, "solution": s, "target_object": o, "hazard_class": c} for o, c, p, s in hyps]}))


def llm_settings(srv, tmp_path, **over):
    s = load_settings(None, {"quiet": True, "workers": 1, "detect.detector": "llm", **over})
    s.llm = llm_config_for(srv, tmp_path, cache=False)
    return s


def scene_responder(req):
    """Answers like a sensible model, per scene; the fridge scene first names an object that is not there."""
    user = _user(req)
    repaired = any(m["role"] == "assistant" for m in req["messages"])
    if "pill_bottle_0" in user:  # free text (no class): judged by SBERT
        return reply(("pill_bottle_0", None,
                      "A bottle of tablets lies on the carpet where small children crawl and could swallow them",
                      "Put the tablet bottle in the medicine cabinet"))
    if "kitchen_knife_0" in user:
        return reply(("mug_0", None, "The mug is in the way", "Move the mug"),
                     ("kitchen_knife_0", "store_sharp_objects", "Knife at the counter edge", "Store the knife"))
    if not repaired:  # a name that matches nothing in the scene, even by retrieval: sent back for repair
        return reply(("flux_capacitor", "close_open_refrigerator", "It hums", "Look at it"))
    return reply(("refrigerator_0", "close_open_refrigerator", "The fridge door is open", "Close the fridge door"))


def test_llm_detector_end_to_end(scripted_server, tmp_path):
    srv = scripted_server(scene_responder)
    run = standard_run(tmp_path)
    summary = run_stage(run, llm_settings(srv, tmp_path))
    assert (summary.done, summary.failed) == (3, 0)
    dets = {d.task_id: d for d in read_jsonl(run.detections_path, Detection)}
    knife = [(h.target_object, h.hazard_class) for h in dets["t-knife"].hypotheses]
    assert knife == [("mug_0", None), ("kitchen_knife_0", "store_sharp_objects")]
    assert [(h.target_object, h.hazard_class) for h in dets["t-pill"].hypotheses] == [("pill_bottle_0", None)]
    assert dets["t-fridge"].hypotheses[0].target_object == "refrigerator_0"
    assert all(d.detector == "llm" and not d.judgements for d in dets.values())
    # the bad object name went back to the model with the validation error, once
    fridge_reqs = [r for r in srv.requests if "refrigerator_0" in _user(r) and "kitchen_knife_0" not in _user(r)]
    assert len(fridge_reqs) == 2 and "target_object" in fridge_reqs[1]["messages"][-1]["content"]
    # the model sees the scene and the class menu, never the task
    for req in srv.requests:
        body = " ".join(m["content"] for m in req["messages"])
        assert "Known hazard classes" in body
        for task in (g.KNIFE_TASK, g.PILL_TASK, g.FRIDGE_TASK):
            assert_no_leak(_user(req).split("Known hazard classes")[0], task)
    # the text judge's diagnostic (evaluate side) judges free text by similarity, the rest exactly
    tj = text_judge_diagnostic(run, list(dets.values()), run.load_tasks(), {}, 3, llm_settings(srv, tmp_path))
    assert tj.hit_at_k[1] == round(2 / 3, 4) and tj.hit_at_k[2] == 1.0 and tj.methods == {"exact": 2, "sbert": 1}
    manifest = run.load_manifest()
    assert manifest.llm_usage.requests == 4
    # the real key reaches the server (settings cross to the item as JSON, which masks secrets)
    assert all(h.get("Authorization", h.get("authorization")) == "Bearer sk-test-not-a-real-key" for h in srv.headers)


def test_a_scene_whose_replies_never_validate_fails_alone(scripted_server, tmp_path):
    def responder(req):
        if "pill_bottle_0" in _user(req):
            return text("I think the pills are dangerous!")  # never JSON
        return scene_responder(req)

    srv = scripted_server(responder)
    run = standard_run(tmp_path)
    summary = run_stage(run, llm_settings(srv, tmp_path))
    assert summary.done == 3  # recorded as a detection with an error, not a crashed batch
    dets = {d.task_id: d for d in read_jsonl(run.detections_path, Detection)}
    assert dets["t-pill"].error and dets["t-pill"].hypotheses == []
    assert dets["t-fridge"].hypotheses[0].target_object == "refrigerator_0"
    # a re-run retries only the failed scene
    again = run_stage(run, llm_settings(srv, tmp_path))
    assert (again.done, again.skipped) == (1, 2)


def test_the_text_judges_llm_is_asked_about_misses(scripted_server, tmp_path):
    def responder(req):
        if "grade a household robot" in _system(req):
            return text(json.dumps({"same_problem": "medicine" in _user(req), "reason": "same pills"}))
        if "pill_bottle_0" in _user(req):
            return reply(("pill_bottle_0", None, "medicine bottle", "tidy"))  # too terse for SBERT
        return scene_responder(req)

    srv = scripted_server(responder)
    run = standard_run(tmp_path)
    settings = llm_settings(srv, tmp_path, **{"evaluate.text_judge_llm": True})
    run_stage(run, settings, only=["t-pill"])
    dets = read_jsonl(run.detections_path, Detection)
    assert not any("grade a household robot" in _system(r) for r in srv.requests)  # detect never judges
    tj = text_judge_diagnostic(run, dets, run.load_tasks(), {}, 3, settings)
    assert tj.hit_at_k[1] == 1.0 and tj.methods == {"llm": 1}


def test_hybrid_llm_reorders_rule_candidates(scripted_server, tmp_path):
    def responder(req):
        listing = _user(req).split("Candidates:")[1]
        assert "1. remove_choking_hazards on marble_0" in listing
        return text(json.dumps({"ranking": [
            {"candidate": 2, "problem": "A knife lies at the counter edge", "solution": "Put it in the cabinet"},
            {"candidate": 1, "problem": "A marble on the floor", "solution": "Pick it up"}]}))

    srv = scripted_server(responder)
    det = HybridDetector(get_client(llm_config_for(srv, tmp_path, cache=False)))
    hyps = det.detect(g.two_hazards(), 3)
    assert [(h.target_object, h.hazard_class) for h in hyps] == [
        ("kitchen_knife_0", "store_sharp_objects"), ("marble_0", "remove_choking_hazards")]
    assert hyps[0].problem == "A knife lies at the counter edge" and "ranked by LLM" in hyps[0].explanation
    assert det.fell_back is None


def test_hybrid_falls_back_to_rule_order_and_says_so(scripted_server, tmp_path):
    srv = scripted_server([status(500)])
    det = HybridDetector(get_client(llm_config_for(srv, tmp_path, cache=False, http_retries=0), backoff_base_s=0.0))
    hyps = det.detect(g.two_hazards(), 3)
    assert [h.hazard_class for h in hyps] == ["remove_choking_hazards", "store_sharp_objects"]
    assert all("rule order kept" in h.explanation for h in hyps)
    assert det.fell_back


def test_hybrid_fills_what_the_llm_left_out_in_rule_order(scripted_server, tmp_path):
    srv = scripted_server([text(json.dumps({"ranking": [
        {"candidate": 2, "problem": "Knife at the edge", "solution": "Store it"}]}))])
    hyps = HybridDetector(get_client(llm_config_for(srv, tmp_path, cache=False))).detect(g.two_hazards(), 3)
    assert [h.target_object for h in hyps] == ["kitchen_knife_0", "marble_0"]
    assert hyps[1].explanation.startswith("not ranked by the LLM; rule order")


def test_llm_detector_grounds_loose_names_without_a_repair(scripted_server, tmp_path):
    """Issue 15: "fridge" and a loose class name are grounded to the scene's instance and a class id."""
    from anomalygen.detect.llm_detector import LLMDetector

    srv = scripted_server([reply(("the fridge", "food warming up", "The fridge door was left open and food warms up",
                                  "Close the fridge door"))])
    detector = LLMDetector(get_client(llm_config_for(srv, tmp_path, cache=False)))
    [hyp] = detector.detect(g.open_fridge(), 3)
    assert (hyp.target_object, hyp.hazard_class) == ("refrigerator_0", "close_open_refrigerator")
    assert "'the fridge' -> refrigerator_0" in hyp.explanation and len(srv.requests) == 1
