"""What the textile literature on measured Cusick drape gave this project, source by source (issue 35 item 5).

Searched on 2026-12-04 through the project's search tool (stored public copies of web pages, documentation,
issue threads and repositories; no live web): the studies that pair mechanical data (KES-F, FAST or
cantilever) with a measured Cusick drape coefficient (DC) or node count. For each: the citation, where a
public copy was found, what of it could be read there, and whether that part holds a table of fabric values.
The tool returns the *opening* of a stored page (title, authors, abstract, table of contents); no table of
fabric values of any of these studies was within reach, so **no fabric row (mechanical data with a measured
DC) could be entered**: :data:`MEASURED_ROWS` is empty, and the report says so.

What the readable openings do give are qualitative findings (paraphrased, not quoted), which the report
checks as trends of the simulation (:data:`TRENDS`). Nothing here is entered from memory: every statement
is what the opening at the given address says.
"""

from __future__ import annotations

SEARCHED = (
    {"citation": "Hu, J. & Chan, Y.F. (1998), Effect of fabric mechanical properties on drape, Text. Res. J. 68(1), "
                 "57-64",
     "found_at": "https://research.polyu.edu.hk/en/publications/effect-of-fabric-mechanical-properties-on-drape",
     "readable": "abstract only",
     "says": "regressions of the Cusick DC on sixteen KES-F properties of woven fabrics; bending and shear "
             "properties are closely related to the DC (also friction deviation MMD and tensile linearity LT)",
     "table_within_reach": False},
    {"citation": "Kenkare, N., Lamar, T.A.M., Pandurangan, P. & Eischen, J. (2008), Enhancing accuracy of drape "
                 "simulation. Part I: Investigation of drape variability via 3D scanning, J. Text. Inst., "
                 "doi:10.1080/00405000701489222 (preprint: Kenkare & May-Plumlee et al., Mechanics of fabric "
                 "drape, Part I and II, TRJ submission 2004)",
     "found_at": "https://pdfslide.net/documents/enhancing-accuracy-of-drape-simulation-part-i-enhancing-accuracy"
                 "-of-drape.html; https://pl.scribd.com/document/23115839/TRJ2004-Paper-1-Final",
     "readable": "title page, abstract and introduction",
     "says": "circular specimens of fabrics with KES-measured properties draped on a Cusick tester and 3D scanned; "
             "the drape of one fabric is highly variable between specimens (no single configuration to target)",
     "table_within_reach": False},
    {"citation": "Kuijpers, A. (2017), Evaluation of physical and virtual fabric drape created from objective "
                 "fabric properties, MPhil thesis, University of Manchester",
     "found_at": "https://dokumen.tips/documents/evaluation-of-physical-and-virtual-fabric-drape-.html",
     "readable": "title page and table of contents",
     "says": "(the contents list only)",
     "table_within_reach": False},
    {"citation": "Sanad, R., Cassidy, T., Cheung, V. & Evans, E. (2013), Fabric and garment drape measurement - "
                 "Part 2, J. Fiber Bioeng. Inform. 6(1), 1-22, doi:10.3993/jfbi03201301",
     "found_at": "https://ro.scribd.com/document/350680699/JFBI-6-1-1",
     "readable": "abstract and introduction",
     "says": "knitted, woven and nonwoven fabrics compared by FAST properties, drape coefficient and image-analysis "
             "drape values",
     "table_within_reach": False},
    {"citation": "Behera, B.K. & Pattanayak, A.K. (2008), Measurement and modeling of drape using digital image "
                 "processing, Indian J. Fibre Text. Res. 33, 230-238",
     "found_at": "https://ja.scribd.com/document/363282421/IJFTR-333-230-238-pdf",
     "readable": "abstract and introduction",
     "says": "drape parameters regressed on KES low-stress properties; good correlation with bending and shear; a "
             "higher drape coefficient goes with fewer nodes",
     "table_within_reach": False},
    {"citation": "Using the FAST system to establish translation equations for the drape coefficient (title as "
                 "stored; authors not in the readable part)",
     "found_at": "https://sciencedocbox.com/amp/109921325-Physics/Using-the-fast-system-to-establish-translation-"
                 "equations-for-the-drape-coefficient.html",
     "readable": "title and a list of unrelated documents",
     "says": "(nothing of the study)",
     "table_within_reach": False},
    {"citation": "Cerda, E., Mahadevan, L. & Pasini, J.M. (2004), The elements of draping, PNAS 101(7), 1806-1810",
     "found_at": "https://scribd.com/document/435887211/1806-full-pdf",
     "readable": "abstract and first page",
     "says": "a sheet draped over a support forms folds whose number is set by the sheet's size against a length "
             "from its weight and bending stiffness; larger sheets show more, and more complex, folds",
     "table_within_reach": False},
    {"citation": "Lahey, T.J. & Heppler, G.R. (2004), Mechanical modeling of fabrics in bending, J. Appl. Mech. "
                 "71(1), 32-40, doi:10.1115/1.1629757",
     "found_at": "https://www.scribd.com/document/23116966/lahey",
     "readable": "abstract and introduction",
     "says": "KES bending loops reproduced by nonlinear elasticity plus viscous and Coulomb friction; the "
             "hysteresis comes from friction between yarns (the model of rftstatic.element.hysteresis is the "
             "Coulomb part)",
     "table_within_reach": False},
    {"citation": "Feng, X., Huang, W., Xu, W. & Wang, H. (2022), Learning-based bending stiffness parameter "
                 "estimation by a drape tester, ACM Trans. Graph. 41(6); github.com/DrapeTester/ClothDrapeTester",
     "found_at": "github.com/DrapeTester/ClothDrapeTester (commit 24a980c), dataset/dataset.csv",
     "readable": "the repository (the library's ctd-* presets come from its data set)",
     "says": "cantilever-derived bending parameters of 618 fabrics; no Cusick DC or node count per fabric in the "
             "repository",
     "table_within_reach": True},
)
"""Every source looked at (module docstring)."""

MEASURED_ROWS: tuple = ()
"""Fabrics with mechanical data and a measured Cusick DC, each with its source table: none could be read."""

TRENDS = {
    "dc_rises_with_bending_length": (
        "At one specimen and disc size, a stiffer fabric (longer bending length c = (B/W)^(1/3)) drapes with a "
        "higher DC. The readable openings say that bending properties correlate with the DC (Hu & Chan 1998; "
        "Behera & Pattanayak 2008), not its sign; the sign is the physical expectation (a rigid sheet: DC 100 %)."),
    "fewer_nodes_at_higher_dc": (
        "A higher DC goes with fewer nodes (Behera & Pattanayak 2008, abstract)."),
    "more_nodes_on_larger_specimens": (
        "At one fabric, a larger sheet folds into more nodes: the fold count is set by the sheet's size against "
        "the bending length (Cerda, Mahadevan & Pasini 2004, abstract)."),
    "dc_rises_with_shear_rigidity": (
        "Shear properties correlate with the DC (Hu & Chan 1998; Behera & Pattanayak 2008; the sign is not in the "
        "readable part): a fabric harder to shear resists the double curvature of folds, so it should drape higher."),
}
"""The qualitative findings of the readable openings that the report checks as trends (keys used there)."""
