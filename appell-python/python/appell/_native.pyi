from typing import List, Tuple

SOURCE_HASH: str
APPELL_HASH: str
GLUE_HASH: str
VERSION: str

def sources() -> List[Tuple[str, bytes]]: ...
