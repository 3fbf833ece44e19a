from typing import List, Tuple

SOURCE_HASH: str
VERSION: str

def sources() -> List[Tuple[str, bytes]]: ...
