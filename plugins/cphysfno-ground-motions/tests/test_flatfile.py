"""The flatfile reader on PEER's _SearchResults.csv: lines about the search above the
table, a table of spectra after it."""

from cphysfno_ground_motions import read_flatfile

SEARCH_RESULTS = """\
 PEER NGA-West2 Ground Motion Database,,,
 Search Parameters,,,
 Magnitude Range,5,7,
,,,
 -- Summary of Metadata of Selected Records --,,,
Result ID,Record Sequence Number,Scale Factor,Earthquake Name,Year,Station Name,Magnitude,\
Mechanism,Rjb (km),Rrup (km),Vs30 (m/sec),Horizontal-1 Acc. Filename,Horizontal-2 Acc. Filename
1,6,1.2345,Imperial Valley-02,1940,El Centro Array #9,6.95,strike slip,6.09,6.09,213.44,\
RSN6_IMPVALL.I_I-ELC180.AT2,RSN6_IMPVALL.I_I-ELC270.AT2
2,953,0.8,Northridge-01,1994,Beverly Hills - 14145 Mulhol,6.69,Reverse,9.44,17.15,355.81,\
RSN953_NORTHR_MUL009.AT2,RSN953_NORTHR_MUL279.AT2

 -- Scaled Spectra used in Search & Scaling --,,,
Period (sec),Target,Arithmetic Mean,
0.01,0.5,0.4,
"""


def test_search_results_give_each_records_metadata_and_peer_scale_factor(tmp_path):
    path = tmp_path / "_SearchResults.csv"
    path.write_text(SEARCH_RESULTS)
    table = read_flatfile(path)
    assert set(table) == {6, 953}
    northridge = table[953]
    assert northridge["event"] == "Northridge-01" and northridge["year"] == 1994
    assert northridge["magnitude"] == 6.69 and northridge["rjb_km"] == 9.44
    assert northridge["vs30"] == 355.81 and northridge["peer_scale_factor"] == 0.8
    assert table[6]["horizontal_1_file"] == "RSN6_IMPVALL.I_I-ELC180.AT2"
