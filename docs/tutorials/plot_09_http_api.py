"""
The HTTP API
============

``bayesgrasp serve`` serves a web page and a JSON API. Every answer is the document the
command line prints with ``--json``. Here the API is called in-process with FastAPI's
``TestClient``; with a running server the same requests go to
``http://127.0.0.1:8000`` (for example with ``curl`` or ``requests``).
"""

# %%
import io
import json
import logging
import tempfile
import warnings

import matplotlib.image as mpimg
import matplotlib.pyplot as plt

with warnings.catch_warnings():  # some starlette versions warn about their test client
    warnings.simplefilter("ignore", DeprecationWarning)
    from fastapi.testclient import TestClient

from bayesgrasp.web.app import create_app

logging.getLogger("httpx").setLevel(logging.WARNING)  # no line a request
client = TestClient(create_app(data_dir=tempfile.mkdtemp()))
print(client.get("/api/v1/health").json())

# %%
# A plan
# ------
# ``POST /api/v1/plan`` takes the part (``catalogue``, ``vertices`` or a ``file``) and
# every option of ``bayesgrasp plan``. The equivalent ``curl`` request::
#
#     curl -s http://127.0.0.1:8000/api/v1/plan -H 'Content-Type: application/json' \
#          -d '{"part": {"vertices": [[0, 0], [40, 0], [10, 20]], "name": "wedge"}}'
body = {"part": {"vertices": [[0, 0], [40, 0], [10, 20]], "name": "wedge", "units": "mm"}}
plan = client.post("/api/v1/plan", json=body).json()
for o in plan["options"]:
    print(o["squeezes"], round(o["success_probability"], 4), round(o["expected_cost"], 3))
print("Bayes plan:", plan["bayes"], "most certain:", plan["most_certain"])

# %%
# Bad input is a 422 with the command line's one-line message:
bad = client.post("/api/v1/plan", json={"part": {"vertices": [[0, 0], [1, 1]]}})
print(bad.status_code, json.dumps(bad.json()))

# %%
# A sensing policy and a simulation
# ---------------------------------
policy = client.post("/api/v1/policy", json={"part": {"catalogue": "house"}, "sense": "width"})
print("policy expected cost:", round(policy.json()["expected_cost"], 4))
sim = client.post("/api/v1/simulate", json={"part": {"catalogue": "house"}, "trials": 10000})
print(
    "simulated success:",
    sim.json()["observed_success"],
    "predicted:",
    round(sim.json()["predicted_success"], 4),
)

# %%
# A figure
# --------
# ``POST /api/v1/figures/plan.png`` returns the plan figure of ``bayesgrasp plot``.
png = client.post("/api/v1/figures/plan.png", json={"part": {"catalogue": "house"}}).content
fig, ax = plt.subplots(figsize=(8, 4))
ax.imshow(mpimg.imread(io.BytesIO(png), format="png"))
ax.set_axis_off()
fig.tight_layout()
