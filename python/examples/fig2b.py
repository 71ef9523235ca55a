"""The paper's Fig. 2b: the precursor length against the shear load, calibration scene."""
import matplotlib.pyplot as plt
import precursors

scene = precursors.Scene()  # the calibration scene: 140 x 7 x 75 mm PMMA, rod drive
driver = scene.driver()
lx = scene.block[0]
mu_fn = driver.friction_coefficient * driver.normal_load
load, length = [], []
for event in driver:
    if event.kind == "stable":
        load.append(event.force / mu_fn)
        length.append(driver.precursor_length / lx)
plt.step(load, length, where="post")
plt.xlabel("F / (μ F_N)"), plt.ylabel("ℓ / Lx")
plt.savefig("fig2b.png", dpi=150)
