"""The Python examples of the documents run as written: every ```python block of a document, in
order and in one namespace, from a folder where the documents' relative paths (datasets/...)
resolve and what they write stays out of the checkout."""

import re

import numpy as np
import pytest

import ridi
from conftest import ROOT, SAMPLE

DOCUMENTS = ["README.md", "docs/python.md", "crates/ridi-py/README.md"]


def python_blocks(text):
    return re.findall(r"^```python\n(.*?)^```", text, flags=re.S | re.M)


# The sample's warnings (a run standing still) are the examples' output, not the test's.
@pytest.mark.filterwarnings("ignore::UserWarning")
@pytest.mark.parametrize("document", DOCUMENTS)
def test_the_python_examples_of_a_document_run(document, tmp_path, monkeypatch):
    blocks = python_blocks((ROOT / document).read_text(encoding="utf-8"))
    assert blocks, f"{document} has no python example"
    (tmp_path / "datasets").symlink_to(ROOT / "datasets", target_is_directory=True)
    monkeypatch.chdir(tmp_path)
    # "Your own phone's arrays": a phone's streams at 100 Hz, from a bundled run.
    phone = ridi.read(SAMPLE / "Thibaud_Nexus5_NoDist_Texting")
    namespace = {
        "t": phone.time[::2],
        "gyro": phone.gyro[::2],
        "acce": phone.acce[::2],
    }
    for block in blocks:
        exec(compile(block, document, "exec"), namespace)
    track = namespace["track"]
    assert track.position.shape[1] == 3 and np.isfinite(track.position).all()
    if "report" in namespace:
        assert np.isfinite(namespace["report"]["summary"]["ridi"]["rte_5s_m"])
