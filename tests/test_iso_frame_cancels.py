"""G69 (rotation off) and G50 (scaling off) read no words, so a block may hold one beside another
frame code: each must act. Before, the block kept one frame function and `G69 G50` silently
left the rotation on. Expected ends are computed by hand."""
import pytest

from nctrans import api

HEAD = "G90 G21 G17\nG0 X0 Y0\n"


def _ends(tmp_path, body: str):
    path = tmp_path / "frames.nc"
    path.write_text(HEAD + body + "M30\n")
    return [(round(r.end["X"], 6), round(r.end["Y"], 6))
            for r in api.toolpath(path, "iso-m") if r.kind == "linear"]


@pytest.mark.parametrize("cancel", ["G69 G50", "G50 G69"])
def test_both_cancels_in_one_block_act(tmp_path, cancel):
    # rotated 90 degrees and scaled x2 about the origin: X10 lands at (0, 20); after the
    # cancels X5 Y0 is (5, 0) again
    ends = _ends(tmp_path, f"G68 X0 Y0 R90\nG51 X0 Y0 P2000\nG1 X10 F100\n{cancel}\nG1 X5 Y0\n")
    assert ends == [(0.0, 20.0), (5.0, 0.0)]


def test_rotation_cancel_beside_scaling_on(tmp_path):
    # G69 ends the rotation, G51 in the same block starts scaling x2: X5 goes to (10, 0)
    ends = _ends(tmp_path, "G68 X0 Y0 R90\nG1 X10 F100\nG69 G51 X0 Y0 P2000\nG1 X5 Y0\nG50\n")
    assert ends == [(0.0, 10.0), (10.0, 0.0)]
