import pytest
from tests.server.conftest import BtClient, clients
from tests.server.test_code_actions import TREES, _at
pytestmark = [pytest.mark.asyncio(loop_scope="module"), clients("vscode")]
async def test_dbg(client: BtClient) -> None:
    uri = client.open(TREES)
    print(await client.diags(uri, 1))
    acts = await client.code_actions(uri, _at(client, TREES, "Sub Tree"))
    print(_at(client, TREES, "Sub Tree"), acts)
    print(client.log_messages)
