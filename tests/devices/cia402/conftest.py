"""The canopen masters of these tests wait for a drive's SDO answer as a
master on a loaded bus would: canopen's 0.3 s default is shorter than the
pause a 2-core CI machine running the suite on both cores can give the
drive's receiving thread, and a missed answer there says nothing about the
drive.  A test that is about the timeout sets its own on the node."""

from __future__ import annotations

import pytest

canopen = pytest.importorskip("canopen")


@pytest.fixture(autouse=True)
def _patient_sdo_master(monkeypatch: pytest.MonkeyPatch) -> None:
    from canopen.sdo.client import SdoClient
    monkeypatch.setattr(SdoClient, "RESPONSE_TIMEOUT", 5.0)
