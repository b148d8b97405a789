"""``make mutation``'s targets still exist: every judging and verdict-assembling function it
mutates is found, and every hand-planted bug of tools/mutation.py (a wrong frame, a dropped
argument, a stale verdict) still finds its one place in its function and changes it — or the
tool would stop planting it without saying so. A structure check, not a correctness one: the
mutation run itself (``make mutation``) is what shows the tests catch the bugs."""

import mutation


def test_every_area_names_functions_that_exist_and_every_planted_bug_has_its_place():
    areas = {target.area: target for target in mutation.TARGETS}
    planted = 0
    for target in mutation.TARGETS:
        _, tree = mutation._source_tree(target.module)
        for function in target.functions:
            mutation._function_node(tree, function)  # raises SystemExit when it is gone
        for mutant in mutation.semantic_mutants(target):  # SystemExit unless found once
            assert mutant.replacement != mutant.text, mutant.description
            planted += 1
    assert planted == len(mutation.SEMANTIC) >= 15
    assert all(area in areas for area, *_ in mutation.SEMANTIC)
