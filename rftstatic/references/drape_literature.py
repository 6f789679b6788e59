"""What the textile literature on measured Cusick drape gave this project, source by source (issues 35 and 37).

Two searches, both on 2026-12-04, through the project's search tool (stored public copies of web pages,
documentation, issue threads and repositories; no live web): for studies that pair mechanical data (KES-F,
FAST or cantilever) with a measured Cusick drape coefficient (DC) or node count (issue 35), and for studies
that compare a flared skirt's folds with the same fabric's Cusick drape (issue 37). The first search gave the
entries of :data:`SEARCHED` marked ``search: 1``; the second (branch h-lit) added those marked ``search: 2``
and :data:`SKIRT_SEARCHED`, and its every query, with what came back, is the CSV read by :func:`search_log`
(``data/drape_search_2026-12-04.csv``, described in SOURCES.md).

The page corpus keeps only the first passages of a stored page (its opening, for some pages the next
passage): a query that names a table's content returns the title, authors, abstract or the introduction's
start, never a results table. No fabric table of any of these studies was within reach, so **no fabric row
(mechanical data with a measured DC, read in its source) could be entered** (:data:`MEASURED_ROWS` is empty) and
**no skirt row** (:data:`SKIRT_ROWS` is empty); the report validation/measured_drape.md says so. A row entered
later must pass :func:`check_row` (the fields of :data:`ROW_FIELDS`), and its table's text must be copied into
the package's data folder.

One table came second-hand: a public repository transcribes four fabrics of Matsudaira et al. (2015) (KES B,
2HB, W, T, drape coefficient and node count). They are :data:`SECONDARY_ROWS`, kept apart from the measured rows,
copied unchanged with their source lines (``data/matsudaira2015_as_transcribed.csv``, :func:`secondary_table`);
the tester's specimen and disc diameters are not in the transcription.

What the readable openings do give are qualitative findings (paraphrased, not quoted), which the report
checks as trends of the simulation (:data:`TRENDS`). Nothing here is entered from memory: every statement
is what the opening at the given address says.
"""

from __future__ import annotations

import csv
import io
import math
from importlib import resources

SEARCH_LOG_FILE = "drape_search_2026-12-04.csv"
"""The second search's log in ``rftstatic/references/data``: one row per query (:func:`search_log`)."""

SEARCH_LOG_COLUMNS = ("corpus", "query", "returned", "what_the_returned_part_held")
"""Columns of :data:`SEARCH_LOG_FILE`: the corpus or verb, the query as sent (non-ASCII queries transliterated
or described), the addresses that came back, and what the part returned held."""

SEARCHED = (
    {"citation": "Hu, J. & Chan, Y.F. (1998), Effect of fabric mechanical properties on drape, Text. Res. J. 68(1), "
                 "57-64",
     "found_at": "https://research.polyu.edu.hk/en/publications/effect-of-fabric-mechanical-properties-on-drape",
     "readable": "abstract only",
     "says": "regressions of the Cusick DC on sixteen KES-F properties of woven fabrics; bending and shear "
             "properties are closely related to the DC (also friction deviation MMD and tensile linearity LT)",
     "table_within_reach": False, "search": 1},
    {"citation": "Kenkare, N., Lamar, T.A.M., Pandurangan, P. & Eischen, J. (2008), Enhancing accuracy of drape "
                 "simulation. Part I: Investigation of drape variability via 3D scanning, J. Text. Inst., "
                 "doi:10.1080/00405000701489222 (preprint: Kenkare & May-Plumlee et al., Mechanics of fabric "
                 "drape, Part I and II, TRJ submission 2004)",
     "found_at": "https://pdfslide.net/documents/enhancing-accuracy-of-drape-simulation-part-i-enhancing-accuracy"
                 "-of-drape.html; https://pl.scribd.com/document/23115839/TRJ2004-Paper-1-Final",
     "readable": "title page, abstract and introduction",
     "says": "circular specimens of fabrics with KES-measured properties draped on a Cusick tester and 3D scanned; "
             "the drape of one fabric is highly variable between specimens (no single configuration to target)",
     "table_within_reach": False, "search": 1},
    {"citation": "Kuijpers, A. (2017), Evaluation of physical and virtual fabric drape created from objective "
                 "fabric properties, MPhil thesis, University of Manchester",
     "found_at": "https://dokumen.tips/documents/evaluation-of-physical-and-virtual-fabric-drape-.html",
     "readable": "title page and table of contents",
     "says": "(the contents list only)",
     "table_within_reach": False, "search": 1},
    {"citation": "Sanad, R., Cassidy, T., Cheung, V. & Evans, E. (2013), Fabric and garment drape measurement - "
                 "Part 2, J. Fiber Bioeng. Inform. 6(1), 1-22, doi:10.3993/jfbi03201301",
     "found_at": "https://ro.scribd.com/document/350680699/JFBI-6-1-1",
     "readable": "abstract and introduction",
     "says": "knitted, woven and nonwoven fabrics compared by FAST properties, drape coefficient and image-analysis "
             "drape values",
     "table_within_reach": False, "search": 1},
    {"citation": "Behera, B.K. & Pattanayak, A.K. (2008), Measurement and modeling of drape using digital image "
                 "processing, Indian J. Fibre Text. Res. 33, 230-238",
     "found_at": "https://ja.scribd.com/document/363282421/IJFTR-333-230-238-pdf",
     "readable": "abstract and introduction",
     "says": "drape parameters regressed on KES low-stress properties; good correlation with bending and shear; a "
             "higher drape coefficient goes with fewer nodes",
     "table_within_reach": False, "search": 1},
    {"citation": "Using the FAST system to establish translation equations for the drape coefficient (title as "
                 "stored; authors not in the readable part)",
     "found_at": "https://sciencedocbox.com/amp/109921325-Physics/Using-the-fast-system-to-establish-translation-"
                 "equations-for-the-drape-coefficient.html",
     "readable": "title and a list of unrelated documents",
     "says": "(nothing of the study)",
     "table_within_reach": False, "search": 1},
    {"citation": "Cerda, E., Mahadevan, L. & Pasini, J.M. (2004), The elements of draping, PNAS 101(7), 1806-1810",
     "found_at": "https://scribd.com/document/435887211/1806-full-pdf",
     "readable": "abstract and first page",
     "says": "a sheet draped over a support forms folds whose number is set by the sheet's size against a length "
             "from its weight and bending stiffness; larger sheets show more, and more complex, folds",
     "table_within_reach": False, "search": 1},
    {"citation": "Lahey, T.J. & Heppler, G.R. (2004), Mechanical modeling of fabrics in bending, J. Appl. Mech. "
                 "71(1), 32-40, doi:10.1115/1.1629757",
     "found_at": "https://www.scribd.com/document/23116966/lahey",
     "readable": "abstract and introduction",
     "says": "KES bending loops reproduced by nonlinear elasticity plus viscous and Coulomb friction; the "
             "hysteresis comes from friction between yarns (the model of rftstatic.element.hysteresis is the "
             "Coulomb part)",
     "table_within_reach": False, "search": 1},
    {"citation": "Feng, X., Huang, W., Xu, W. & Wang, H. (2022), Learning-based bending stiffness parameter "
                 "estimation by a drape tester, ACM Trans. Graph. 41(6); github.com/DrapeTester/ClothDrapeTester",
     "found_at": "github.com/DrapeTester/ClothDrapeTester (commit 24a980c), dataset/dataset.csv",
     "readable": "the repository (the library's ctd-* presets come from its data set)",
     "says": "cantilever-derived bending parameters of 618 fabrics; no Cusick DC or node count per fabric in the "
             "repository",
     "table_within_reach": True, "search": 1},
    {"citation": "Pan, N., Lin, C. & Xu, J. (2019), A new method for measuring fabric drape with a novel "
                 "parameter for classifying fabrics, Fibers 7(8), 70, doi:10.3390/fib7080070",
     "found_at": "https://www.mdpi.com/2079-6439/7/8/70; https://docslib.org/doc/5970439",
     "readable": "journal header, affiliations, abstract and the first words of the introduction",
     "says": "40 fabrics tested; a fabric linear density (lambda) sorts fabrics into four groups, and the "
             "PhabrOmeter's extraction test is offered in place of the Cusick drapemeter, which the authors find "
             "of low repeatability and sensitivity",
     "table_within_reach": False, "search": 2},
    {"citation": "Gider, A. (2004), An online fabric database to link fabric drape and end-use properties, MS "
                 "thesis, Louisiana State University, https://digitalcommons.lsu.edu/gradschool_theses/3902",
     "found_at": "https://docslib.org/doc/8646215",
     "readable": "the repository's cover sheet, the title page and the acknowledgements",
     "says": "(nothing of the fabrics or their drape)",
     "table_within_reach": False, "search": 2},
    {"citation": "Chu, C.C., Hamburger, W.J. & Platt, M.M. (OCR: Piatt) (1963), Determination of factors which "
                 "influence the draping properties of cotton fabrics, USDA Agricultural Research Service report "
                 "ARS 72-17",
     "found_at": "https://archive.org/ (the stored address names no item)",
     "readable": "cover, acknowledgement, title page and errata",
     "says": "a report of research for the USDA on the drape of cotton fabrics (its data are past the errata)",
     "table_within_reach": False, "search": 2},
    {"citation": "Jeong, Y.J. & Phillips, D.G. (1998), A study of fabric-drape behaviour with image analysis. "
                 "Part I: Measurement, characterisation, and instability (the series of Part II, J. Text. Inst.)",
     "found_at": "https://paperexplained.cn/articles/paper/detail/43fc7f4ae7786a50a5d7c8c05a942bd9aa313b15",
     "readable": "title and abstract",
     "says": "the drape value depends on the number of nodes, which depends on the fabric's initial state and "
             "varies between repeated tests of one fabric; the drape value at the most frequent node number is "
             "proposed as the standard value",
     "table_within_reach": False, "search": 2},
    {"citation": "Jeong, Y.J. & Phillips, D.G. (1998), A study of fabric-drape behaviour with image analysis. "
                 "Part II: The effects of fabric structure and mechanical properties on fabric drape, J. Text. "
                 "Inst. 89(1), 70-79, doi:10.1080/00405009808658598",
     "found_at": "https://tomorrow.paperai.life/https://www.scribd.com/document/661790907/drape8",
     "readable": "the publisher's cover page",
     "says": "(nothing of the study)",
     "table_within_reach": False, "search": 2},
    {"citation": "Shyr, T.W., Wang, P.N. & Cheng, K.B., A comparison of the key parameters affecting the dynamic "
                 "and static drape coefficients of natural-fibre woven fabrics by a newly devised dynamic drape "
                 "automatic measuring system (journal and year not in the part returned)",
     "found_at": "https://ja.scribd.com/document/253502683",
     "readable": "affiliations and abstract",
     "says": "four natural-fibre woven fabrics, sixteen KES-F properties, static and dynamic DC; the bending and "
             "shear blocks of properties are the ones most associated with the static and dynamic DC",
     "table_within_reach": False, "search": 2},
    {"citation": "Sule, G. (2012), Investigation of bending and drape properties of woven fabrics and the effects "
                 "of fabric constructional parameters and warp tension on these properties, Text. Res. J. 82(8), "
                 "810-819, doi:10.1177/0040517511433152",
     "found_at": "https://scribd.com/document/489386088/sule2012",
     "readable": "the publisher's cover page and the abstract's first sentences",
     "says": "fabrics woven with thicker weft yarns and at higher weft density are stiffer in bending; the warp "
             "bending rigidity rises with the warp tension",
     "table_within_reach": False, "search": 2},
    {"citation": "Matusiak, M. (2017), Influence of the structural parameters of woven fabrics on their "
                 "drapeability, Fibres Text. East. Eur. 25(1)",
     "found_at": "https://europub.co.uk/articles/influence-of-the-structural-parameters-of-woven-fabrics-on-their-"
                 "drapeability-A-199556",
     "readable": "abstract",
     "says": "cotton woven fabrics differing in weave and weft yarn measured on a drape tester; stiffness is the "
             "property that most influences their drape; the weave changes the DC and the shape factor",
     "table_within_reach": False, "search": 2},
    {"citation": "Sanad, R.A.E. (2013), The measurement of drape for nonwoven and conventional textile fabrics, "
                 "PhD thesis, University of Leeds",
     "found_at": "https://www.scribd.com/document/726454504/Final-Thesis-3",
     "readable": "title page, declaration and acknowledgements",
     "says": "(nothing of the fabrics; the thesis behind Sanad et al. 2012 and 2013)",
     "table_within_reach": False, "search": 2},
    {"citation": "Mei, Z., Shen, W., Wang, Y., Yang, J., Zhou, T. & Zhou, H. (2015), Unidirectional fabric drape "
                 "testing method, PLoS ONE, doi:10.1371/journal.pone.0143648 (year not in the part returned)",
     "found_at": "http://www.plosone.org/article/info%3Adoi%2F10.1371%2Fjournal.pone.0143648; "
                 "https://pdfslide.us/documents/unidirectional-fabric-drape-testing-method.html",
     "readable": "author list and abstract",
     "says": "a drape test with gravity along the fabric plane, captured in 3D; its values correlate with the "
             "traditional (Cusick-type) test and with subjective ratings",
     "table_within_reach": False, "search": 2},
    {"citation": "Multidimensional analysis for fabric drapability, Fashion and Textiles (SpringerOpen), "
                 "doi:10.1186/s40691-023-00352-w (authors not in the part returned)",
     "found_at": "https://fashionandtextiles.springeropen.com/articles/10.1186/s40691-023-00352-w",
     "readable": "abstract and the first sentence of the introduction",
     "says": "fabrics with similar DC can drape into different shapes; node location and the spread of node "
             "severity tell them apart where the DC cannot",
     "table_within_reach": False, "search": 2},
    {"citation": "Predicting the drape coefficient from KES-FB and CLO Fabric Kit measurements, J. Eng. Fibers "
                 "Fabr., doi:10.1177/15589250231174610 (title paraphrased; authors and year not in the part returned)",
     "found_at": "https://sage.cnpereading.com/doi/10.1177/15589250231174610",
     "readable": "abstract and the introduction's first paragraph",
     "says": "the DC regressed on KES-FB properties, and predicted for a new fabric from the most similar fabric "
             "of a database; no difference found between predicted and measured DC",
     "table_within_reach": False, "search": 2},
    {"citation": "A sustainable framework for realism evaluation and optimization of virtual fabric drape effect, "
                 "Sustainability 17(12), 5550 (2025), doi:10.3390/su17125550",
     "found_at": "https://www.mdpi.com/2071-1050/17/12/5550/xml",
     "readable": "journal header and abstract",
     "says": "virtual drape tests set up after real drape tests, their realism graded in six levels by subjective "
             "rating and a neural network",
     "table_within_reach": False, "search": 2},
    {"citation": "Fabric drape coefficient testing (a topic page without author or source)",
     "found_at": "https://mapofsciences.com/topic/drape-coefficient-testing/",
     "readable": "the whole page",
     "says": "typical DC and node-count ranges stated without a source or a named fabric: not a measurement, "
             "not used",
     "table_within_reach": False, "search": 2},
    {"citation": "Matsudaira, M., Masuda, T., Wada, M. & Yokura, H. (2015), Shape factor of flared skirts compared "
                 "with that of circular fabrics, J. Textile Eng. 61(6), 69-73, doi:10.4188/jte.61.69",
     "found_at": "not the paper: a transcription of its Tables 1 and 2 in the public repository "
                 "github.com/antonbj3/3fold-motion-engine (commit 72e280a), src/motion_engine/cloth/r6_setup.py and "
                 "data/cloth/bending_and_drape_reference.json (read_file)",
     "readable": "the transcription: KES B and 2HB, W, T, DC and node count of four fabrics (A, B, C, F); the "
                 "paper itself (J-STAGE) is not stored here",
     "says": "four fabrics with KES bending data and a measured drape coefficient and node count "
             "(SECONDARY_ROWS); the transcription names Table 1 (KES) and Table 2 (drape), gives one B per "
             "fabric (no warp / weft split), leaves out the shear G it says the table carries, and does not "
             "give the drape tester's specimen and disc diameters",
     "table_within_reach": False, "search": 2},
    {"citation": "Memon, H., Chaklie, E.B., Yesuf, H.M. & Zhu, C. (2021), Study on effect of leather rigidity and "
                 "thickness on drapability of sheep garment leather, Materials 14(16), 4553, "
                 "doi:10.3390/ma14164553",
     "found_at": "https://mdpi.com/1996-1944/14/16/4553 (and a mirror); https://ebusca.uv.mx/Record/"
                 "pubmed-8398511/Details",
     "readable": "abstract and the introduction's first paragraph (the page's first two passages)",
     "says": "four sheep garment leathers: flexural rigidity 9.2 to 22 and thickness 0.64 to 0.96 (units not in "
             "the part returned), mean DC 47.35 to 69.9 %; no per-sample values in reach",
     "table_within_reach": False, "search": 2},
)
"""Every source looked at for issue 35 (module docstring); ``search`` says which of the two searches found it."""

SKIRT_SEARCHED = (
    {"citation": "A study of the drape of women's skirt styles against fabric drape: congress.sctm.mk, event 5, "
                 "contribution 487 (title and authors not in the part returned)",
     "found_at": "https://congress.sctm.mk/event/5/contributions/487",
     "readable": "the abstract",
     "says": "full-circle and half-circle skirts of one cut length, of fabrics of 157.6 to 296.5 g/m2 with "
             "Cusick DC 46.5 to 93.6 %, on a mannequin; draped areas seen from four sides correlated with the "
             "fabrics' DC, thickness and mass and with the number of nodes; front against the other sides "
             "correlates at 0.96-0.98 for the full circle, 0 to 0.7 for the half circle; no per-fabric values",
     "table_within_reach": False, "search": 2},
    {"citation": "Sanad, R., Cassidy, T., Cheung, V. & Evans, E. (2013), Fabric and garment drape measurement - "
                 "Part 2, J. Fiber Bioeng. Inform. 6(1), 1-22, doi:10.3993/jfbi03201301",
     "found_at": "https://ro.scribd.com/document/350680699/JFBI-6-1-1",
     "readable": "abstract and introduction",
     "says": "dresses on a mannequin against the fabrics' drape by image analysis: most drape values of fabric "
             "and garment correlate poorly",
     "table_within_reach": False, "search": 2},
    {"citation": "Flared skirts and fabric properties, KAKENHI project 63580074, 1989 report (Japanese; the "
                 "investigators not in the part returned)",
     "found_at": "https://kaken.nii.ac.jp/ja/report/KAKENHI-PROJECT-63580074/635800741989jisseki",
     "readable": "the report's summary",
     "says": "flared skirts of 22 cotton, wool and polyester fabrics from one pattern: the weft cantilever "
             "stiffness correlates best with the silhouette; more flare (0 to 120 cm) leaves the silhouette and "
             "changes the number and depth of the folds; no drape-tester reading, no per-fabric values",
     "table_within_reach": False, "search": 2},
    {"citation": "Masteikaite, V., Saceviciene, V., Januleviciene, D., Igembajeva, G. & Nurjasarova, M., Drape "
                 "analysis of fabrics used for outerwear, Indian J. Fibre Text. Res.",
     "found_at": "http://op.niscair.res.in/index.php/IJFTR/article/view/3588",
     "readable": "abstract",
     "says": "three wool and wool-blend fabrics, cantilever bending rigidity, specimens cut as the side part of a "
             "cape: the fold geometry depends on the garment's construction as well as on the fabric",
     "table_within_reach": False, "search": 2},
    {"citation": "Kenkare, N., May-Plumlee, T., Pandurangan, P. & Eischen, J., Mechanics of fabric drape, Part "
                 "II: Generation of optimal simulations (TRJ submission 2004)",
     "found_at": "https://www.scribd.com/document/23115840/TRJ2004-Paper-2-Final",
     "readable": "abstract and introduction",
     "says": "a relationship from KES properties to particle-model inputs, fitted on circular specimens, tried "
             "on simulations of apparel; no garment against Cusick numbers in the part returned",
     "table_within_reach": False, "search": 2},
    {"citation": "Matsudaira, M., Masuda, T., Wada, M. & Yokura, H. (2015), Shape factor of flared skirts compared "
                 "with that of circular fabrics, J. Textile Eng. 61(6), 69-73, doi:10.4188/jte.61.69",
     "found_at": "the paper is not stored here; its fabrics' KES data and drape, as a third party transcribed "
                 "them, are SECONDARY_ROWS",
     "readable": "the title (in the transcription's citation); no skirt value",
     "says": "by its title, the study that issue 37 asks for (flared skirts against the same fabrics' circular "
             "drape); its skirt numbers were not reached",
     "table_within_reach": False, "search": 2},
    {"citation": "Flared skirts made by two flat-pattern methods and by draping (koreascience.or.kr, "
                 "JAKO200823659446695; authors not in the part returned)",
     "found_at": "https://koreascience.or.kr/article/JAKO200823659446695.view?orgId=ksci",
     "readable": "the abstract",
     "says": "the draped-pattern skirt has more uniform nodes than the flat-pattern skirts; a lining reduces "
             "the node count of the flat-pattern skirts; no fabric drape values",
     "table_within_reach": False, "search": 2},
    {"citation": "Local deformation of flared skirts of four fabrics (J-STAGE, senshoshi 57(10); Japanese; "
                 "authors not in the part returned)",
     "found_at": "https://www.jstage.jst.go.jp/browse/senshoshi/57/10/_contents/-char/ja",
     "readable": "the abstract (Japanese)",
     "says": "sheeting, broadcloth, satin crepe and cupra skirts after two weeks: local deformation correlates "
             "with the fabrics' bending and shear properties (p < 0.01); no drape-tester reading",
     "table_within_reach": False, "search": 2},
)
"""Every source looked at for issue 37 (a flared skirt's folds against the same fabric's Cusick drape)."""

ROW_FIELDS = {
    "citation": "the study, as in :data:`SEARCHED`",
    "url": "the public copy the values were read from",
    "where": "table (and page) of the values in that copy",
    "copy": "file name, in rftstatic/references/data, of the table's text as read, with its source line",
    "fabric": "the fabric's label as printed",
    "printed": "dict: column header as printed -> value as printed (strings, units in the header)",
    "kes_B_warp": "bending rigidity, warp [gf cm^2/cm]",
    "kes_B_weft": "bending rigidity, weft [gf cm^2/cm]",
    "kes_W": "weight per area [mg/cm^2]",
    "kes_T": "thickness [mm], or None if not given",
    "specimen_diameter_cm": "the drape specimen's diameter [cm]",
    "disc_diameter_cm": "the supporting disc's diameter [cm]",
    "dc_percent": "measured drape coefficient [%]",
    "nodes": "measured node count, or None if not given",
}
"""The fields of a measured fabric row (:data:`MEASURED_ROWS`), checked by :func:`check_row`; numbers in the
units named, converted from ``printed`` by the stated factor (1 g/m^2 = 0.1 mg/cm^2)."""

MEASURED_ROWS: tuple = ()
"""Fabrics with mechanical data and a measured Cusick DC, each with its source table: none could be read."""

SKIRT_ROWS: tuple = ()
"""Fabrics with a measured flared-skirt fold count and the same fabric's Cusick DC or nodes: none could be
read (:data:`SKIRT_SEARCHED`)."""


SECONDARY_FILE = "matsudaira2015_as_transcribed.csv"
"""In ``rftstatic/references/data``: the four rows of :data:`SECONDARY_ROWS` as the transcription gives them,
with its source lines (:func:`secondary_table`)."""

SECONDARY_ROWS = (
    {"fabric": "A", "name": "cotton broad", "kes_B": 0.118, "kes_2HB": 0.124, "kes_W": 12.38, "kes_T": 0.497,
     "dc_percent": 82.9, "nodes": 2},
    {"fabric": "B", "name": "wool tropical", "kes_B": 0.067, "kes_2HB": 0.033, "kes_W": 16.29, "kes_T": 0.407,
     "dc_percent": 49.8, "nodes": 5},
    {"fabric": "C", "name": "polyester tropical", "kes_B": 0.077, "kes_2HB": 0.029, "kes_W": 11.65,
     "kes_T": 0.340, "dc_percent": 50.7, "nodes": 5},
    {"fabric": "F", "name": "polyester faille", "kes_B": 0.019, "kes_2HB": 0.007, "kes_W": 10.43, "kes_T": 0.226,
     "dc_percent": 28.3, "nodes": 7},
)
"""Matsudaira et al. (2015), Tables 1 and 2, **as a third party transcribed them** (github.com/antonbj3/3fold-
motion-engine, commit 72e280a, src/motion_engine/cloth/r6_setup.py), not read in the paper: KES-FB2 bending
rigidity B [gf cm^2/cm] (one value per fabric, so warp = weft here) and hysteresis 2HB [gf cm/cm], weight W
[mg/cm^2], thickness T [mm], drape coefficient [%] and node count. Unknown from it: the drape tester's specimen
and disc diameters, B's warp / weft split, the shear G. Not :data:`MEASURED_ROWS`: a row there must be read in
the source; these are kept apart so that a report can show them as what they are."""


def check_row(row: dict) -> None:
    """Raise ``ValueError`` naming the field, its value and the rule when ``row`` is not a valid measured row.

    Rules: every field of :data:`ROW_FIELDS` present; text fields non-empty; ``copy`` a file of the package's
    data folder; B_warp, B_weft, W > 0 and T > 0 or None; 0 < disc diameter < specimen diameter [cm];
    0 <= DC <= 100 [%]; nodes a non-negative integer or None.
    """
    missing = [k for k in ROW_FIELDS if k not in row]
    if missing:
        raise ValueError(f"row of {row.get('citation', '?')!r}: missing field(s) {missing}; a row has "
                         f"{list(ROW_FIELDS)}")
    for key in ("citation", "url", "where", "copy", "fabric"):
        if not isinstance(row[key], str) or not row[key].strip():
            raise ValueError(f"row {row['fabric']!r}: {key} = {row[key]!r}, must be non-empty text")
    if not isinstance(row["printed"], dict) or not row["printed"]:
        raise ValueError(f"row {row['fabric']!r}: printed = {row['printed']!r}, must map headers to values")
    if not resources.files("rftstatic.references").joinpath("data", row["copy"]).is_file():
        raise ValueError(f"row {row['fabric']!r}: copy = {row['copy']!r} is not a file of "
                         "rftstatic/references/data; copy the table's text there")

    def positive(key, optional=False):
        v = row[key]
        if optional and v is None:
            return
        if not isinstance(v, (int, float)) or not math.isfinite(v) or v <= 0:
            raise ValueError(f"row {row['fabric']!r}: {key} = {v!r}, must be > 0 ({ROW_FIELDS[key]})")

    for key in ("kes_B_warp", "kes_B_weft", "kes_W", "specimen_diameter_cm", "disc_diameter_cm"):
        positive(key)
    positive("kes_T", optional=True)
    if row["disc_diameter_cm"] >= row["specimen_diameter_cm"]:
        raise ValueError(f"row {row['fabric']!r}: disc_diameter_cm = {row['disc_diameter_cm']!r} is not below "
                         f"specimen_diameter_cm = {row['specimen_diameter_cm']!r}")
    dc = row["dc_percent"]
    if not isinstance(dc, (int, float)) or not 0.0 <= dc <= 100.0:
        raise ValueError(f"row {row['fabric']!r}: dc_percent = {dc!r}, must be in [0, 100]")
    nodes = row["nodes"]
    if nodes is not None and (isinstance(nodes, bool) or not isinstance(nodes, int) or nodes < 0):
        raise ValueError(f"row {row['fabric']!r}: nodes = {nodes!r}, must be a non-negative integer or None")


def search_log() -> list[dict]:
    """The second search's queries: one dict per row of :data:`SEARCH_LOG_FILE`, keyed by
    :data:`SEARCH_LOG_COLUMNS` (read with :mod:`importlib.resources`, so found wherever the package is)."""
    text = resources.files("rftstatic.references").joinpath("data", SEARCH_LOG_FILE).read_text(encoding="utf-8")
    reader = csv.DictReader(io.StringIO(text))
    if tuple(reader.fieldnames or ()) != SEARCH_LOG_COLUMNS:
        raise ValueError(f"{SEARCH_LOG_FILE}: columns = {reader.fieldnames}, expected {list(SEARCH_LOG_COLUMNS)}")
    return list(reader)



def secondary_table() -> list[dict]:
    """The rows of :data:`SECONDARY_FILE` (its ``#`` lines are the source), values as text exactly as copied."""
    text = resources.files("rftstatic.references").joinpath("data", SECONDARY_FILE).read_text(encoding="utf-8")
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.startswith("#")]
    return list(csv.DictReader(io.StringIO("\n".join(lines))))

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
