"""The cantilever bending tester (ASTM D1388 option A) on a fabric given in KES-F lab units: the run finds
the overhang at which the strip's tip meets the 41.5 deg plane and prints the bending length c = l / 2,
beside the bending length (B / W)^(1/3) of the values it was given."""

import tempfile

from rftstatic import api

lab = {"kes_B_warp": 0.083, "kes_B_weft": 0.06,      # KES-FB2 bending rigidity [gf cm^2/cm]
       "kes_G": 0.7,                                 # KES-FB1 shear rigidity [gf/(cm deg)]
       "kes_EMT_warp": 3.0, "kes_EMT_weft": 4.0,     # KES-FB1 extension at 500 gf/cm [%]
       "kes_W": 25.0}                                # areal weight [mg/cm^2]

data = api.load_scene("cantilever-warp").data        # cases/cantilever-warp.toml as a dict
data["material"] = {"warp_angle": 0.0, **lab}        # the lab data instead of the preset
data["element"] = "RFT3"
data["mesh"]["nodes"] = [17, 5]
scene = api.scene_from_dict(data, name="cantilever-kes")   # checked as a scene file is
with tempfile.TemporaryDirectory() as out:
    result = api.run(scene, out, figures=False)

c = result.summary["cantilever"]["bending_length"]
W = lab["kes_W"] / 1000.0                            # [gf/cm^2]
print(f"given (B/W)^(1/3): {(lab['kes_B_warp'] / W) ** (1 / 3):.4f} cm")
print(f"bending length: {c:.4f} cm")
