"""Nothing lost: a restart of the server (a new application on the same data folder) keeps a
finished session's grade and resumes an unfinished one where its log ended."""

from __future__ import annotations

import json

from tests.web.conftest import TOKEN, ask, claim_all, make_client, open_socket, start


def test_a_restart_keeps_grades_and_resumes_sessions(tmp_path):
    with make_client(tmp_path) as c1:
        done_sid, done_secret = start(c1, trainee="finished")
        claim_all(c1, done_sid, done_secret)
        grade1 = c1.app.state.registry.grading(done_sid).result(timeout=60)
        open_sid, open_secret = start(c1, trainee="unfinished")
        ws, conn, hello = open_socket(c1, open_sid, open_secret)
        f = hello["state"]["controls"]["f_instrument"]
        before = ask(
            conn,
            {
                "action": {
                    "kind": "set",
                    "control": "f_instrument",
                    "value": round((f["min"] + f["max"]) / 2, 2),
                },
                "seq": 1,
            },
        )
        before = ask(conn, {"action": {"kind": "turn", "control": "X", "delta": 1.5}, "seq": 2})
        ws.__exit__(None, None, None)
        assert before["error"] is None and before["n"] == 2
    with make_client(tmp_path) as c2:  # the restarted server
        r = c2.get(f"/api/sessions/{done_sid}/grade", params={"key": done_secret})
        assert r.status_code == 200 and r.json()["grade"] == grade1
        assert c2.app.state.registry.grading(done_sid) is None  # kept, not regraded
        rows = {
            r["id"]: r for r in c2.get("/api/instructor/sessions", params={"token": TOKEN}).json()
        }
        assert rows[done_sid]["score"] == round(grade1["overall"]["score"], 4)
        assert rows[open_sid]["actions"] == 2 and not rows[open_sid]["done"]
        ws, conn, hello = open_socket(c2, open_sid, open_secret)  # the page reconnects
        try:
            assert hello["n"] == 2 and hello["state"] == before["state"]
            after = ask(conn, {"action": {"kind": "read", "counter": "X"}, "seq": 3})
            assert after["error"] is None and after["n"] == 3
        finally:
            ws.__exit__(None, None, None)
        log = c2.get(f"/api/sessions/{open_sid}/log.jsonl", params={"token": TOKEN}).text
        records = [json.loads(line) for line in log.splitlines()]
        assert [r["n"] for r in records[1:]] == [1, 2, 3]
        assert records[3]["t"] >= records[2]["t"]  # the server's clock runs on
