from typing import Optional

class Error(Exception):
    message: str
    file: Optional[str]
    line: Optional[int]
    column: Optional[int]
    key: Optional[str]
    detail: str
    def __init__(self, message: str, file: str = ..., line: int = ..., column: int = ...,
                 key: str = ..., detail: str = ...) -> None: ...

class CaseError(Error): ...
class InternalError(Error): ...
